#include "resizable_item.hpp"

#include <QGraphicsSceneMouseEvent>
#include <QPainter>
#include <algorithm>

namespace vrflow::editor::gui {

namespace {

constexpr double kHandleSize = 12;  // side of the square handle, scene units

}  // namespace

void ResizableItem::setSize(QSizeF size) {
  if (size == size_) return;
  prepareGeometryChange();
  size_ = size;
}

bool ResizableItem::onHandle(QPointF pos) const {
  return pos.x() >= size_.width() - kHandleSize && pos.y() >= size_.height() - kHandleSize &&
         pos.x() <= size_.width() && pos.y() <= size_.height();
}

void ResizableItem::drawHandle(QPainter* painter, QColor color) const {
  painter->setPen(QPen(color, 1.2));
  for (double d = 3; d < kHandleSize; d += 4) {
    painter->drawLine(QPointF(size_.width() - d, size_.height() - 2),
                      QPointF(size_.width() - 2, size_.height() - d));
  }
}

void ResizableItem::mousePressEvent(QGraphicsSceneMouseEvent* event) {
  if (event->button() == Qt::LeftButton && onHandle(event->pos())) {
    resizing_ = true;
    event->accept();
    return;
  }
  QGraphicsItem::mousePressEvent(event);
}

void ResizableItem::mouseMoveEvent(QGraphicsSceneMouseEvent* event) {
  if (resizing_) {
    setSize(QSizeF(std::max(minimum_.width(), event->pos().x()),
                   std::max(minimum_.height(), event->pos().y())));
    return;
  }
  QGraphicsItem::mouseMoveEvent(event);
}

void ResizableItem::mouseReleaseEvent(QGraphicsSceneMouseEvent* event) {
  resizing_ = false;
  QGraphicsItem::mouseReleaseEvent(event);
}

}  // namespace vrflow::editor::gui
