#include "frame_item.hpp"

#include <QGraphicsScene>
#include <QGraphicsSceneMouseEvent>
#include <QPainter>
#include <algorithm>

#include "inplace_text_item.hpp"
#include "node_item.hpp"
#include "note_item.hpp"
#include "resize_handle.hpp"

namespace vrflow::editor::gui {

namespace {

constexpr double kTitleHeight = 22;

}  // namespace

FrameItem::FrameItem(std::string id, QSizeF size, QString title, QColor color)
    : id_(std::move(id)), size_(size), title_(std::move(title)), color_(color) {
  setFlags(ItemIsMovable | ItemIsSelectable | ItemSendsGeometryChanges);
  setZValue(-1);  // behind connections and nodes
}

QRectF FrameItem::boundingRect() const {
  return QRectF(QPointF(-2, -2), size_ + QSizeF(4, 4));
}

void FrameItem::setSize(QSizeF size) {
  if (size == size_) return;
  prepareGeometryChange();
  size_ = size;
}

void FrameItem::setTitle(const QString& title) {
  title_ = title;
  update();
}

void FrameItem::setColor(QColor color) {
  color_ = color;
  update();
}

void FrameItem::paint(QPainter* painter, const QStyleOptionGraphicsItem*, QWidget*) {
  painter->setRenderHint(QPainter::Antialiasing);
  const QRectF box(QPointF(0, 0), size_);
  QColor fill = color_;
  fill.setAlpha(40);
  painter->setBrush(fill);
  painter->setPen(isSelected() ? QPen(QColor(255, 170, 0), 2.5) : QPen(color_, 1.5));
  painter->drawRoundedRect(box, 8, 8);
  QColor band = color_;
  band.setAlpha(170);
  painter->save();
  QPainterPath clip;
  clip.addRoundedRect(box, 8, 8);
  painter->setClipPath(clip);
  painter->fillRect(QRectF(0, 0, size_.width(), kTitleHeight), band);
  painter->restore();
  QFont font = painter->font();
  font.setPointSizeF(9.5);
  font.setBold(true);
  painter->setFont(font);
  painter->setPen(Qt::white);
  painter->drawText(QRectF(10, 0, size_.width() - 20, kTitleHeight),
                    Qt::AlignLeft | Qt::AlignVCenter, title_);
  drawResizeHandle(painter, size_, color_.darker(130));
}

void FrameItem::editTitle() {
  auto* editor = new InPlaceTextItem(this, title_, false,
                                     [id = id_, callback = titleEdited](const QString& t) {
                                       if (callback) callback(id, t);
                                     });
  editor->setPos(6, 0);
  editor->setDefaultTextColor(Qt::black);
}

void FrameItem::mousePressEvent(QGraphicsSceneMouseEvent* event) {
  if (event->button() == Qt::LeftButton && onResizeHandle(event->pos(), size_)) {
    resizing_ = true;
    event->accept();
    return;
  }
  carried_.clear();
  if (event->button() == Qt::LeftButton && scene() != nullptr) {
    // What lies inside (by its top-left corner, as moveFrame() decides) moves with the frame.
    const QRectF area(scenePos(), size_);
    for (QGraphicsItem* item : scene()->items(area)) {
      if (item->isSelected() || item->parentItem() != nullptr) continue;
      if (dynamic_cast<NodeItem*>(item) == nullptr && dynamic_cast<NoteItem*>(item) == nullptr)
        continue;
      if (area.contains(item->scenePos())) carried_.push_back(item);
    }
  }
  lastPos_ = pos();
  QGraphicsItem::mousePressEvent(event);
}

void FrameItem::mouseMoveEvent(QGraphicsSceneMouseEvent* event) {
  if (resizing_) {
    setSize(QSizeF(std::max(80.0, event->pos().x()), std::max(50.0, event->pos().y())));
    return;
  }
  QGraphicsItem::mouseMoveEvent(event);
}

void FrameItem::mouseReleaseEvent(QGraphicsSceneMouseEvent* event) {
  resizing_ = false;
  QGraphicsItem::mouseReleaseEvent(event);
  carried_.clear();
}

void FrameItem::mouseDoubleClickEvent(QGraphicsSceneMouseEvent* event) {
  if (event->button() == Qt::LeftButton && event->pos().y() <= kTitleHeight) {
    editTitle();
    event->accept();
    return;
  }
  QGraphicsItem::mouseDoubleClickEvent(event);
}

QVariant FrameItem::itemChange(GraphicsItemChange change, const QVariant& value) {
  if (change == ItemPositionHasChanged) {
    const QPointF delta = pos() - lastPos_;
    lastPos_ = pos();
    for (QGraphicsItem* item : carried_) item->moveBy(delta.x(), delta.y());
  }
  return QGraphicsItem::itemChange(change, value);
}

}  // namespace vrflow::editor::gui
