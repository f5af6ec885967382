#include "inplace_text_item.hpp"

#include <QKeyEvent>
#include <QTextCursor>
#include <QTimer>

namespace vrflow::editor::gui {

InPlaceTextItem::InPlaceTextItem(QGraphicsItem* parent, const QString& text, bool multiLine,
                                 std::function<void(const QString&)> finished)
    : QGraphicsTextItem(parent), multiLine_(multiLine), finished_(std::move(finished)) {
  setPlainText(text);
  setTextInteractionFlags(Qt::TextEditorInteraction);
  setZValue(10);
  setFocus(Qt::MouseFocusReason);
  QTextCursor cursor = textCursor();
  cursor.select(QTextCursor::Document);
  setTextCursor(cursor);
}

void InPlaceTextItem::focusOutEvent(QFocusEvent* event) {
  QGraphicsTextItem::focusOutEvent(event);
  finish(true);
}

void InPlaceTextItem::keyPressEvent(QKeyEvent* event) {
  const bool enter = event->key() == Qt::Key_Return || event->key() == Qt::Key_Enter;
  if (event->key() == Qt::Key_Escape) {
    finish(false);
    return;
  }
  if (enter && (!multiLine_ || (event->modifiers() & Qt::ControlModifier))) {
    finish(true);
    return;
  }
  QGraphicsTextItem::keyPressEvent(event);
}

void InPlaceTextItem::finish(bool keep) {
  if (done_) return;
  done_ = true;
  const QString text = toPlainText();
  setTextInteractionFlags(Qt::NoTextInteraction);
  hide();
  // The callback may rebuild the item this text sits on: leave the event first.
  auto finished = finished_;
  QTimer::singleShot(0, [finished, text, keep] {
    if (keep) finished(text);
  });
  deleteLater();
}

}  // namespace vrflow::editor::gui
