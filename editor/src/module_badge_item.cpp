#include "module_badge_item.hpp"

#include <QFontMetricsF>
#include <QPainter>
#include <algorithm>

namespace vrflow::editor::gui {

namespace {

constexpr double kBadgeHeight = 40;
constexpr double kGap = 4;
const QColor kFailed(210, 30, 30);

}  // namespace

ModuleBadgeItem::ModuleBadgeItem(QGraphicsItem* node, QSizeF nodeSize)
    : QGraphicsObject(node), nodeSize_(nodeSize) {
  setPos(0, nodeSize.height() + kGap);
  setAcceptHoverEvents(true);
}

void ModuleBadgeItem::setFigures(const BadgeFigures& figures) {
  prepareGeometryChange();
  figures_ = figures;
  lines_.clear();
  QString first = figures.state.isEmpty() ? QString("starting") : figures.state;
  if (figures.modules > 1) first = QString("%1 modules").arg(figures.modules);
  lines_ << QString("%1 \u00b7 %2 it/s").arg(first).arg(figures.rate, 0, 'f', 1);
  lines_ << QString("wait %1% \u00b7 compute %2%")
                .arg(figures.waitShare * 100, 0, 'f', 0)
                .arg((1 - figures.waitShare) * 100, 0, 'f', 0);
  lines_ << QString("CPU %1 cores \u00b7 %2 MiB")
                .arg(figures.cpu, 0, 'f', 2)
                .arg(figures.rssMiB, 0, 'f', 1);
  if (failed()) lines_ << "failed: " + figures.failure;
  setToolTip(QString("%1 iterations\n").arg(figures.iterations) + lines_.join("\n"));
  update();
}

QRectF ModuleBadgeItem::boundingRect() const {
  QRectF r(0, 0, nodeSize_.width(), kBadgeHeight + (failed() ? 26 : 0));
  // On failure the outline goes around the node's body, above this item.
  if (failed())
    r = r.united(
        QRectF(-4, -nodeSize_.height() - kGap - 4, nodeSize_.width() + 8, nodeSize_.height() + 8));
  return r;
}

void ModuleBadgeItem::paint(QPainter* painter, const QStyleOptionGraphicsItem*, QWidget*) {
  painter->setRenderHint(QPainter::Antialiasing);
  const double w = nodeSize_.width();
  const QRectF box(0, 0, w, kBadgeHeight + (failed() ? 26 : 0));
  painter->setPen(QPen(failed() ? kFailed : QColor(150, 156, 166), 1));
  painter->setBrush(QColor(255, 255, 255, 240));
  painter->drawRoundedRect(box, 4, 4);
  QFont font = painter->font();
  font.setPointSizeF(7);
  painter->setFont(font);
  painter->setPen(QColor(30, 40, 55));
  painter->drawText(QRectF(4, 1, w - 8, 12), Qt::AlignLeft | Qt::AlignVCenter, lines_.value(0));

  // The wait vs compute bar (wait grey, compute green) on the left half, the sparkline of the
  // rate over the last minute on the right half.
  const QRectF bar(4, 15, w / 2 - 8, 8);
  painter->setPen(Qt::NoPen);
  painter->setBrush(QColor(200, 204, 210));
  painter->drawRect(bar);
  painter->setBrush(QColor(60, 160, 90));
  painter->drawRect(QRectF(bar.x() + bar.width() * figures_.waitShare, bar.y(),
                           bar.width() * (1 - figures_.waitShare), bar.height()));
  const QRectF spark(w / 2 + 2, 13, w / 2 - 6, 12);
  const auto& history = figures_.history;
  if (history.size() >= 2) {
    const double top = std::max(1e-9, *std::max_element(history.begin(), history.end()));
    QPolygonF line;
    for (std::size_t i = 0; i < history.size(); ++i) {
      line << QPointF(spark.left() + spark.width() * static_cast<double>(i) /
                                         static_cast<double>(history.size() - 1),
                      spark.bottom() - spark.height() * history[i] / top);
    }
    painter->setPen(QPen(QColor(40, 90, 190), 1.2));
    painter->setBrush(Qt::NoBrush);
    painter->drawPolyline(line);
  }
  painter->setPen(QColor(30, 40, 55));
  painter->drawText(QRectF(4, 26, w - 8, 12), Qt::AlignLeft | Qt::AlignVCenter, lines_.value(2));
  if (failed()) {
    painter->setPen(kFailed);
    const QString cause =
        QFontMetricsF(font).elidedText(lines_.value(3), Qt::ElideRight, 2 * (w - 8));
    painter->drawText(QRectF(4, 39, w - 8, 26), Qt::AlignLeft | Qt::TextWrapAnywhere, cause);
    painter->setPen(QPen(kFailed, 3));
    painter->setBrush(Qt::NoBrush);
    painter->drawRoundedRect(
        QRectF(-3, -nodeSize_.height() - kGap - 3, w + 6, nodeSize_.height() + 6), 7, 7);
  }
}

}  // namespace vrflow::editor::gui
