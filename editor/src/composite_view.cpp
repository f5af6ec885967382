#include "composite_view.hpp"

#include <QEvent>
#include <QHBoxLayout>
#include <QKeyEvent>
#include <QLabel>
#include <QToolButton>
#include <QVBoxLayout>

#include "canvas.hpp"
#include "vrflow/editor/analysis.hpp"

namespace vrflow::editor::gui {

CompositeView::CompositeView(Canvas* parent, app::Application inside, const app::Catalog& catalog,
                             const QString& path)
    : QWidget(parent),
      inside_(std::move(inside)),
      canvas_(new Canvas),
      path_(new QLabel(path)),
      back_(new QToolButton) {
  setObjectName("compositeView");
  setAutoFillBackground(true);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->setSpacing(0);
  auto* bar = new QWidget;
  bar->setObjectName("breadcrumb");
  auto* barLayout = new QHBoxLayout(bar);
  barLayout->setContentsMargins(6, 3, 6, 3);
  back_->setText("\u25C0 Back");
  back_->setToolTip("Back to the application (Esc)");
  barLayout->addWidget(back_);
  path_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  barLayout->addWidget(path_, 1);
  layout->addWidget(bar);
  layout->addWidget(canvas_, 1);
  connect(back_, &QToolButton::clicked, this, &CompositeView::closeRequested);

  canvas_->setReadOnly(true);
  CanvasState& state = canvas_->state();
  state.app = &inside_;
  state.catalog = &catalog;
  // Composites have no positions of their own: the automatic layout places their nodes.
  canvas_->rebuild();
  state.fallback = autoLayout(inside_, canvas_->nodeSizes());
  canvas_->rebuild();

  parent->installEventFilter(this);
  canvas_->installEventFilter(this);
  setGeometry(parent->rect());
  show();
  raise();
  canvas_->fitAll();
  canvas_->setFocus();
}

QString CompositeView::breadcrumb() const {
  return path_->text();
}

bool CompositeView::eventFilter(QObject* watched, QEvent* event) {
  if (watched == parentWidget() && event->type() == QEvent::Resize) {
    setGeometry(parentWidget()->rect());
  } else if (watched == canvas_ && event->type() == QEvent::KeyPress &&
             static_cast<QKeyEvent*>(event)->key() == Qt::Key_Escape) {
    Q_EMIT closeRequested();
    return true;
  }
  return QWidget::eventFilter(watched, event);
}

}  // namespace vrflow::editor::gui
