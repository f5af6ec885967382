#include "canvas_overlay.hpp"

#include <QEvent>
#include <QHBoxLayout>
#include <QKeyEvent>
#include <QLabel>
#include <QToolButton>
#include <QVBoxLayout>

namespace vrflow::editor::gui {

CanvasOverlay::CanvasOverlay(QWidget* parent, const QString& path, const QString& name)
    : QWidget(parent), path_(new QLabel(path)), back_(new QToolButton) {
  setObjectName(name);
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
  connect(back_, &QToolButton::clicked, this, &CanvasOverlay::closeRequested);
}

void CanvasOverlay::setContent(QWidget* content) {
  content_ = content;
  static_cast<QVBoxLayout*>(layout())->addWidget(content, 1);
  parentWidget()->installEventFilter(this);
  content->installEventFilter(this);
  setGeometry(parentWidget()->rect());
  show();
  raise();
}

QString CanvasOverlay::breadcrumb() const {
  return path_->text();
}

bool CanvasOverlay::eventFilter(QObject* watched, QEvent* event) {
  if (watched == parentWidget() && event->type() == QEvent::Resize) {
    setGeometry(parentWidget()->rect());
  } else if (watched == content_ && event->type() == QEvent::KeyPress &&
             static_cast<QKeyEvent*>(event)->key() == Qt::Key_Escape) {
    Q_EMIT closeRequested();
    return true;
  }
  return QWidget::eventFilter(watched, event);
}

}  // namespace vrflow::editor::gui
