#include "link_item.hpp"

#include <QFontMetricsF>
#include <QLineF>
#include <QPainter>
#include <algorithm>

#include "connection_load_item.hpp"

namespace vrflow::editor::gui {

namespace {

// Where the segment from the centre of `r` towards `towards` leaves `r`.
QPointF edgeOf(const QRectF& r, QPointF towards) {
  const QPointF c = r.center();
  const QPointF d = towards - c;
  if (d.isNull()) return c;
  const double sx = d.x() != 0 ? r.width() / 2 / std::abs(d.x()) : 1e9;
  const double sy = d.y() != 0 ? r.height() / 2 / std::abs(d.y()) : 1e9;
  return c + d * std::min({sx, sy, 1.0});
}

}  // namespace

LinkItem::LinkItem(QString a, QString b) : a_(std::move(a)), b_(std::move(b)) {
  setZValue(2);  // over the nodes: groups of hosts overlap on a canvas laid out by data flow
  setAcceptHoverEvents(true);
}

void LinkItem::place(QRectF groupA, QRectF groupB, QColor colorA, QColor colorB) {
  prepareGeometryChange();
  from_ = edgeOf(groupA, groupB.center());
  to_ = edgeOf(groupB, groupA.center());
  colorA_ = colorA;
  colorB_ = colorB;
  update();
}

void LinkItem::setRates(const QStringList& lines, bool lost) {
  prepareGeometryChange();
  lines_ = lines;
  lost_ = lost;
  setToolTip("between hosts " + a_ + " and " + b_ + "\n" + lines.join("\n"));
  update();
}

void LinkItem::setLabelOnHover(bool onHover) {
  labelOnHover_ = onHover;
  setAcceptHoverEvents(true);
  update();
}

void LinkItem::hoverEnterEvent(QGraphicsSceneHoverEvent*) {
  hovered_ = true;
  update();
}

void LinkItem::hoverLeaveEvent(QGraphicsSceneHoverEvent*) {
  hovered_ = false;
  update();
}

QRectF LinkItem::labelRect() const {
  const QFontMetricsF metrics(overlayFont(7.5));
  double width = 0;
  for (const auto& line : lines_) width = std::max(width, metrics.horizontalAdvance(line));
  const double height = metrics.height() * static_cast<double>(lines_.size()) + 4;
  const QPointF mid = (from_ + to_) / 2;
  return QRectF(mid.x() - width / 2 - 4, mid.y() - height / 2, width + 8, height);
}

QRectF LinkItem::boundingRect() const {
  return QRectF(from_, to_).normalized().adjusted(-12, -12, 12, 12).united(labelRect());
}

void LinkItem::paint(QPainter* painter, const QStyleOptionGraphicsItem*, QWidget*) {
  painter->setRenderHint(QPainter::Antialiasing);
  const QLineF line(from_, to_);
  if (line.length() < 1) return;
  // Two lanes, one per direction, each in its sending host's colour.
  const QLineF normal = line.normalVector().unitVector();
  const QPointF side = (normal.p2() - normal.p1()) * 4;
  for (int lane = 0; lane < 2; ++lane) {
    QColor color = lost_ ? QColor(210, 30, 30) : (lane == 0 ? colorA_ : colorB_);
    color.setAlpha(120);
    QPen pen(color, 5, Qt::DashLine, Qt::FlatCap);
    painter->setPen(pen);
    const QPointF shift = lane == 0 ? side : -side;
    painter->drawLine(QLineF(from_ + shift, to_ + shift));
  }
  if (!labelShown()) return;
  const QRectF r = labelRect();
  painter->setPen(QPen(lost_ ? QColor(210, 30, 30) : QColor(120, 126, 136), 1));
  painter->setBrush(QColor(255, 255, 255, 235));
  painter->drawRoundedRect(r, 3, 3);
  painter->setFont(overlayFont(7.5));
  painter->setPen(QColor(30, 40, 55));
  painter->drawText(r, Qt::AlignCenter, lines_.join("\n"));
}

}  // namespace vrflow::editor::gui
