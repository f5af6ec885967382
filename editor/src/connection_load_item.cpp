#include "connection_load_item.hpp"

#include <QFontMetricsF>
#include <QPainter>
#include <algorithm>

namespace vrflow::editor::gui {

QFont overlayFont(double pointSize) {
  QFont font;
  font.setPointSizeF(pointSize);
  return font;
}

QColor colorOfFill(double fill) {
  if (fill < 0) return QColor(150, 156, 166);  // unbounded: no fill to show
  const QColor green(60, 170, 80), amber(240, 170, 0), red(220, 40, 30);
  const double f = std::clamp(fill, 0.0, 1.0);
  const QColor& a = f < 0.5 ? green : amber;
  const QColor& b = f < 0.5 ? amber : red;
  const double t = f < 0.5 ? f * 2 : (f - 0.5) * 2;
  const auto mix = [t](int x, int y) { return static_cast<int>(x + (y - x) * t + 0.5); };
  return QColor(mix(a.red(), b.red()), mix(a.green(), b.green()), mix(a.blue(), b.blue()));
}

ConnectionLoadItem::ConnectionLoadItem(QGraphicsItem* connection, QPainterPath curve,
                                       QPointF middle)
    : QGraphicsObject(connection), curve_(std::move(curve)), middle_(middle) {
  setFlag(ItemStacksBehindParent);
  setAcceptHoverEvents(true);
}

void ConnectionLoadItem::setLoad(double fill, const QString& label, const QString& tooltip) {
  prepareGeometryChange();
  color_ = colorOfFill(fill);
  label_ = label;
  setToolTip(tooltip);
  update();
}

void ConnectionLoadItem::hoverEnterEvent(QGraphicsSceneHoverEvent*) {
  hovered_ = true;
  update();
}

void ConnectionLoadItem::hoverLeaveEvent(QGraphicsSceneHoverEvent*) {
  hovered_ = false;
  update();
}

QRectF ConnectionLoadItem::labelRect() const {
  if (label_.isEmpty()) return {};
  const double width = QFontMetricsF(overlayFont()).horizontalAdvance(label_) + 8;
  // Just below the curve's middle, so that the curve stays visible.
  return QRectF(middle_.x() - width / 2, middle_.y() + 6, width, 13);
}

QRectF ConnectionLoadItem::boundingRect() const {
  return curve_.boundingRect().united(labelRect()).adjusted(-2, -2, 2, 2);
}

void ConnectionLoadItem::paint(QPainter* painter, const QStyleOptionGraphicsItem*, QWidget*) {
  painter->setRenderHint(QPainter::Antialiasing);
  QColor band = color_;
  band.setAlpha(150);
  painter->setPen(Qt::NoPen);
  painter->setBrush(band);
  painter->drawPath(curve_);
  if (!labelShown()) return;
  const QRectF r = labelRect();
  painter->setPen(QPen(color_, 1));
  painter->setBrush(QColor(255, 255, 255, 230));
  painter->drawRoundedRect(r, 3, 3);
  painter->setFont(overlayFont());
  painter->setPen(QColor(30, 40, 55));
  painter->drawText(r, Qt::AlignCenter, label_);
}

}  // namespace vrflow::editor::gui
