#include "quick_add.hpp"

#include <QApplication>
#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QVBoxLayout>

namespace vrflow::editor::gui {

namespace {

// "module core spring" is shown as "spring  (core module)"; the spec rides along.
QString labelOf(const QString& spec) {
  const QStringList parts = spec.split(' ', Qt::SkipEmptyParts);
  if (parts.size() == 3) return parts[2] + "  (" + parts[1] + " module)";
  if (parts.size() == 2) return parts[1] + "  (filter)";
  return spec;
}

}  // namespace

QuickAdd::QuickAdd(QWidget* parent)
    : QFrame(parent), search_(new QLineEdit), list_(new QListWidget) {
  setObjectName("quickAdd");
  setFrameShape(QFrame::StyledPanel);
  setAutoFillBackground(true);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(4, 4, 4, 4);
  auto* title = new QLabel;
  title->setObjectName("quickAddTitle");
  layout->addWidget(title);
  layout->addWidget(search_);
  layout->addWidget(list_);
  search_->setPlaceholderText("Type to search node types");
  search_->setClearButtonEnabled(true);
  search_->installEventFilter(this);
  list_->setMinimumHeight(180);
  resize(280, 260);
  hide();
  connect(search_, &QLineEdit::textChanged, this, &QuickAdd::filter);
  connect(search_, &QLineEdit::returnPressed, this, &QuickAdd::choose);
  connect(list_, &QListWidget::itemActivated, this, &QuickAdd::choose);
  // Clicking elsewhere closes the popup.
  connect(qApp, &QApplication::focusChanged, this, [this](QWidget*, QWidget* now) {
    if (isVisible() && now != nullptr && now != this && !isAncestorOf(now)) hide();
  });
}

void QuickAdd::open(QPoint at, const QStringList& specs, const QString& text,
                    const QString& title) {
  specs_ = specs;
  findChild<QLabel*>("quickAddTitle")->setText(title);
  list_->clear();
  for (const QString& spec : specs_) {
    auto* item = new QListWidgetItem(labelOf(spec), list_);
    item->setData(Qt::UserRole, spec);
    item->setToolTip(spec);
  }
  search_->setText(text);
  filter(text);
  // Inside the parent, even at its right or bottom edge.
  const QSize room = parentWidget()->size() - size();
  move(std::clamp(at.x(), 0, std::max(0, room.width())),
       std::clamp(at.y(), 0, std::max(0, room.height())));
  show();
  raise();
  search_->setFocus();
}

QStringList QuickAdd::shownSpecs() const {
  QStringList shown;
  for (int row = 0; row < list_->count(); ++row) {
    if (!list_->item(row)->isHidden()) shown << list_->item(row)->data(Qt::UserRole).toString();
  }
  return shown;
}

void QuickAdd::filter(const QString& text) {
  const QStringList needles = text.split(' ', Qt::SkipEmptyParts);
  QListWidgetItem* first = nullptr;
  for (int row = 0; row < list_->count(); ++row) {
    QListWidgetItem* item = list_->item(row);
    const QString spec = item->data(Qt::UserRole).toString();
    // Each word typed starts a word of the spec ("co sp" finds "module core spring").
    const QStringList specWords = spec.split(' ', Qt::SkipEmptyParts);
    const bool match = std::all_of(needles.begin(), needles.end(), [&](const QString& needle) {
      return std::any_of(specWords.begin(), specWords.end(), [&](const QString& word) {
        return word.startsWith(needle, Qt::CaseInsensitive);
      });
    });
    item->setHidden(!match);
    if (match && first == nullptr) first = item;
  }
  list_->setCurrentItem(first);
}

void QuickAdd::choose() {
  QListWidgetItem* item = list_->currentItem();
  if (item == nullptr || item->isHidden()) return;
  const QString spec = item->data(Qt::UserRole).toString();
  hide();
  Q_EMIT chosen(spec);
}

bool QuickAdd::eventFilter(QObject* watched, QEvent* event) {
  if (watched == search_ && event->type() == QEvent::KeyPress) {
    const auto* key = static_cast<QKeyEvent*>(event);
    if (key->key() == Qt::Key_Escape) {
      hide();
      parentWidget()->setFocus();
      return true;
    }
    if (key->key() == Qt::Key_Down || key->key() == Qt::Key_Up) {
      // Moves through the shown rows only.
      const int step = key->key() == Qt::Key_Down ? 1 : -1;
      for (int row = list_->currentRow() + step; row >= 0 && row < list_->count(); row += step) {
        if (!list_->item(row)->isHidden()) {
          list_->setCurrentRow(row);
          break;
        }
      }
      return true;
    }
  }
  return QFrame::eventFilter(watched, event);
}

}  // namespace vrflow::editor::gui
