#include "note_item.hpp"

#include <QGraphicsSceneMouseEvent>
#include <QPainter>

#include "inplace_text_item.hpp"

namespace vrflow::editor::gui {

NoteItem::NoteItem(std::string id, QSizeF size, QString text)
    : ResizableItem(size, QSizeF(40, 24)), id_(std::move(id)), text_(std::move(text)) {
  setFlags(ItemIsMovable | ItemIsSelectable);
  setZValue(0.5);  // above connections and frames, below nodes
  setToolTip("Note: double-click to edit; drag the corner to resize");
}

QRectF NoteItem::boundingRect() const {
  return QRectF(QPointF(-2, -2), size() + QSizeF(6, 6));
}

void NoteItem::setText(const QString& text) {
  text_ = text;
  update();
}

void NoteItem::paint(QPainter* painter, const QStyleOptionGraphicsItem*, QWidget*) {
  painter->setRenderHint(QPainter::Antialiasing);
  const QRectF box(QPointF(0, 0), size());
  painter->setPen(Qt::NoPen);
  painter->setBrush(QColor(0, 0, 0, 30));
  painter->drawRect(box.translated(3, 3));
  painter->setBrush(QColor(255, 243, 170));
  painter->setPen(isSelected() ? QPen(QColor(255, 170, 0), 2) : QPen(QColor(214, 190, 90), 1));
  painter->drawRect(box);
  QFont font = painter->font();
  font.setPointSizeF(8.5);
  painter->setFont(font);
  painter->setPen(QColor(60, 52, 20));
  painter->drawText(box.adjusted(6, 4, -6, -4), Qt::AlignLeft | Qt::AlignTop | Qt::TextWordWrap,
                    text_);
  drawHandle(painter, QColor(170, 150, 70));
}

void NoteItem::editText() {
  new InPlaceTextItem(this, text_, true, [this, id = id_, callback = textEdited](const QString& t) {
    if (callback) callback(id, t);
  });
}

void NoteItem::mouseDoubleClickEvent(QGraphicsSceneMouseEvent* event) {
  if (event->button() == Qt::LeftButton) {
    editText();
    event->accept();
    return;
  }
  QGraphicsItem::mouseDoubleClickEvent(event);
}

}  // namespace vrflow::editor::gui
