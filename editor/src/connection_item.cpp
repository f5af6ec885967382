#include "connection_item.hpp"

#include <QPainter>
#include <QPainterPathStroker>
#include <QPolygonF>

namespace vrflow::editor::gui {

ConnectionItem::ConnectionItem(std::size_t index, QPainterPath path, QColor color, bool stampsOnly)
    : index_(index), path_(std::move(path)), color_(color), stampsOnly_(stampsOnly) {
  setFlags(ItemIsSelectable);
  setZValue(0);
  mid_ = path_.pointAtPercent(0.5);
}

void ConnectionItem::setPath(const QPainterPath& path) {
  if (path == path_) return;
  prepareGeometryChange();
  path_ = path;
  mid_ = path_.pointAtPercent(0.5);
  update();
}

QRectF ConnectionItem::boundingRect() const {
  return path_.boundingRect()
      .adjusted(-8, -8, 8, 8)
      .united(QRectF(mid_ - QPointF(90, 22), QSizeF(180, 44)));
}

QPainterPath ConnectionItem::shape() const {
  QPainterPathStroker stroker;
  stroker.setWidth(10);
  return stroker.createStroke(path_);
}

void ConnectionItem::paint(QPainter* painter, const QStyleOptionGraphicsItem*, QWidget*) {
  painter->setRenderHint(QPainter::Antialiasing);
  QPen pen(color_, stampsOnly_ ? 1.5 : 2.5);
  if (stampsOnly_) pen.setStyle(Qt::DashLine);
  if (problem_ == 1) pen.setColor(QColor(240, 170, 0));
  if (problem_ >= 2) {
    pen.setColor(QColor(220, 30, 30));
    pen.setWidthF(3.5);
  }
  if (problem_ == 3) pen.setStyle(Qt::DashDotLine);
  if (isSelected()) {
    QPen glow(QColor(255, 200, 0, 160), pen.widthF() + 5);
    painter->setPen(glow);
    painter->drawPath(path_);
  }
  painter->setPen(pen);
  painter->setBrush(Qt::NoBrush);
  painter->drawPath(path_);
  // Arrow head at the input.
  const QPointF end = path_.pointAtPercent(1);
  painter->setBrush(pen.color());
  painter->setPen(Qt::NoPen);
  QPolygonF head;
  head << end << end + QPointF(-9, -4.5) << end + QPointF(-9, 4.5);
  painter->drawPolygon(head);
  // Labels (run figures, "deadlock") are items of their own, above the nodes.
}

}  // namespace vrflow::editor::gui
