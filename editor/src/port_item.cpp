#include "port_item.hpp"

#include <QPainter>

#include "canvas_style.hpp"
#include "qt_text.hpp"

namespace vrflow::editor::gui {

namespace {

constexpr double kPortRadius = 5;
constexpr double kTokenRadius = 3;
constexpr double kTokenStep = 8;
constexpr int kTokensDrawn = 3;  // more are written "×N"

}  // namespace

PortItem::PortItem(QGraphicsItem* parent, std::string node, app::PortSpec spec)
    : QGraphicsItem(parent), node_(std::move(node)), spec_(std::move(spec)) {
  setAcceptHoverEvents(true);
  QString tip = qtText(spec_.name) + (spec_.isInput ? " (input)" : " (output)") +
                "\ndata: " + qtText(spec_.data);
  if (spec_.stampsOnly) tip += ", stamps only";
  if (spec_.required) tip += "\nrequired";
  if (!spec_.doc.empty()) tip += "\n" + qtText(spec_.doc);
  setToolTip(tip);
}

void PortItem::setTokens(int count) {
  if (count == tokens_) return;
  prepareGeometryChange();
  tokens_ = count;
  update();
}

QRectF PortItem::boundingRect() const {
  const double r = kPortRadius + 3;
  QRectF box(-r, -r, 2 * r, 2 * r);
  // Tokens sit above the incoming wire, left of the port.
  if (tokens_ > 0) box = box.united(QRectF(-44, -16, 44, 12));
  return box;
}

void PortItem::paint(QPainter* painter, const QStyleOptionGraphicsItem*, QWidget*) {
  painter->setRenderHint(QPainter::Antialiasing);
  QColor fill = spec_.stampsOnly ? QColor(200, 200, 200) : colorOfData(spec_.data);
  QPen pen(Qt::white, 1.5);
  if (highlight_ > 0) pen = QPen(QColor(30, 200, 60), 3);
  if (highlight_ < 0) pen = QPen(QColor(220, 30, 30), 3);
  painter->setPen(pen);
  painter->setBrush(fill);
  painter->drawEllipse(QPointF(0, 0), kPortRadius, kPortRadius);
  if (tokens_ <= 0) return;
  painter->setPen(QPen(QColor(40, 44, 52), 1));
  painter->setBrush(QColor(250, 250, 250));
  const int dots = tokens_ > kTokensDrawn ? 1 : tokens_;
  for (int i = 0; i < dots; ++i)
    painter->drawEllipse(QPointF(-9 - kTokenStep * i, -10), kTokenRadius, kTokenRadius);
  if (tokens_ > kTokensDrawn) {
    QFont font = painter->font();
    font.setPointSizeF(7);
    painter->setFont(font);
    painter->drawText(QRectF(-44, -16, 30, 12), Qt::AlignRight | Qt::AlignVCenter,
                      QString("\u00d7%1").arg(tokens_));
  }
}

}  // namespace vrflow::editor::gui
