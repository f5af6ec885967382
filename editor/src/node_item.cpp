#include "node_item.hpp"

#include <QFontMetricsF>
#include <QPainter>
#include <algorithm>
#include <cmath>

namespace vrflow::editor::gui {

namespace {

constexpr double kModuleWidth = 190;
constexpr double kHeader = 42;
constexpr double kRow = 18;
constexpr double kFilterWidth = 130;

}  // namespace

NodeItem::NodeItem(std::string id, NodeKind kind, QString title, QString subtitle, QColor hostColor,
                   QString hostName, const std::vector<app::PortSpec>& ports)
    : id_(std::move(id)),
      kind_(kind),
      title_(std::move(title)),
      subtitle_(std::move(subtitle)),
      hostColor_(hostColor),
      hostName_(std::move(hostName)) {
  setFlags(ItemIsMovable | ItemIsSelectable);
  setZValue(1);
  std::vector<app::PortSpec> ins, outs;
  for (const auto& p : ports) (p.isInput ? ins : outs).push_back(p);
  const std::size_t rows = std::max(ins.size(), outs.size());
  if (kind_ == NodeKind::Filter) {
    const double h = std::max(96.0, static_cast<double>(rows) * kRow * 2.2 + 24);
    size_ = {kFilterWidth, h};
    const double cx = kFilterWidth / 2;
    const double cy = h / 2;
    auto place = [&](const std::vector<app::PortSpec>& list, bool input) {
      for (std::size_t i = 0; i < list.size(); ++i) {
        const double offset =
            (static_cast<double>(i) - (static_cast<double>(list.size()) - 1) / 2) * kRow;
        const double y = cy + offset;
        const double inset = cx * std::abs(offset) / cy;
        auto* port = new PortItem(this, id_, list[i]);
        port->setPos(input ? inset : kFilterWidth - inset, y);
        port->setLabelSide(input);
        ports_.push_back(port);
      }
    };
    place(ins, true);
    place(outs, false);
  } else {
    size_ = {kModuleWidth,
             kHeader + static_cast<double>(std::max<std::size_t>(rows, 1)) * kRow + 8};
    for (std::size_t i = 0; i < ins.size(); ++i) {
      auto* port = new PortItem(this, id_, ins[i]);
      port->setPos(0, kHeader + static_cast<double>(i) * kRow + kRow / 2);
      ports_.push_back(port);
    }
    for (std::size_t i = 0; i < outs.size(); ++i) {
      auto* port = new PortItem(this, id_, outs[i]);
      port->setPos(kModuleWidth, kHeader + static_cast<double>(i) * kRow + kRow / 2);
      ports_.push_back(port);
    }
  }
}

QRectF NodeItem::boundingRect() const {
  // Room for port labels outside rhombi, the marker, the badge and the run text below.
  return QRectF(-80, -14, size_.width() + 160, size_.height() + 44);
}

QPainterPath NodeItem::shape() const {
  QPainterPath path;
  if (kind_ == NodeKind::Filter) {
    const double w = size_.width(), h = size_.height();
    path.moveTo(w / 2, 0);
    path.lineTo(w, h / 2);
    path.lineTo(w / 2, h);
    path.lineTo(0, h / 2);
    path.closeSubpath();
  } else {
    path.addRoundedRect(QRectF(QPointF(0, 0), size_), 6, 6);
  }
  return path;
}

void NodeItem::setProblems(int level, const QString& text) {
  problemLevel_ = level;
  setToolTip(text);
  update();
}

void NodeItem::setRunInfo(const QString& text, bool failed) {
  runInfo_ = text;
  failed_ = failed;
  update();
}

void NodeItem::paint(QPainter* painter, const QStyleOptionGraphicsItem*, QWidget*) {
  painter->setRenderHint(QPainter::Antialiasing);
  const double w = size_.width(), h = size_.height();
  const bool selected = isSelected();
  QPen outline(selected ? QColor(255, 200, 0) : QColor(40, 44, 52), selected ? 2.5 : 1.2);
  if (failed_) outline = QPen(QColor(220, 30, 30), 3.5);
  if (kind_ == NodeKind::Instance) outline.setStyle(Qt::DashLine);
  const QPainterPath body = shape();
  painter->setPen(Qt::NoPen);
  painter->setBrush(QColor(0, 0, 0, 40));
  painter->drawPath(body.translated(3, 3));
  painter->setBrush(QColor(58, 62, 72));
  painter->drawPath(body);

  QFont titleFont = painter->font();
  titleFont.setPointSizeF(9.5);
  titleFont.setBold(true);
  QFont smallFont = painter->font();
  smallFont.setPointSizeF(7.5);

  if (kind_ == NodeKind::Filter) {
    // Host colour as a band through the middle of the rhombus.
    painter->save();
    painter->setClipPath(body);
    QColor band = hostColor_;
    band.setAlpha(200);
    painter->fillRect(QRectF(0, h / 2 - 20, w, 40), band);
    painter->restore();
    painter->setPen(Qt::white);
    painter->setFont(titleFont);
    painter->drawText(QRectF(0, h / 2 - 20, w, 22), Qt::AlignCenter, title_);
    painter->setFont(smallFont);
    painter->drawText(QRectF(0, h / 2, w, 18), Qt::AlignCenter, subtitle_);
  } else {
    painter->save();
    painter->setClipPath(body);
    painter->fillRect(QRectF(0, 0, w, kHeader), hostColor_);
    painter->restore();
    painter->setPen(Qt::white);
    painter->setFont(titleFont);
    painter->drawText(QRectF(8, 3, w - 16, 20), Qt::AlignLeft | Qt::AlignVCenter, title_);
    painter->setFont(smallFont);
    const QFontMetricsF metrics(smallFont);
    const double hostWidth = metrics.horizontalAdvance(hostName_) + 8;
    painter->drawText(QRectF(8, 22, w - 16 - hostWidth, 16), Qt::AlignLeft | Qt::AlignVCenter,
                      metrics.elidedText(subtitle_, Qt::ElideRight, w - 16 - hostWidth));
    painter->drawText(QRectF(8, 22, w - 16, 16), Qt::AlignRight | Qt::AlignVCenter, hostName_);
  }
  // Port names.
  painter->setFont(smallFont);
  for (const PortItem* port : ports_) {
    const QPointF p = port->pos();
    const bool implicit =
        port->spec().name == app::kBeginItPort || port->spec().name == app::kEndItPort;
    painter->setPen(implicit ? QColor(150, 155, 165) : QColor(230, 232, 236));
    const QString name = QString::fromStdString(port->spec().name);
    if (kind_ == NodeKind::Filter) {
      QRectF r = port->spec().isInput ? QRectF(p.x() - 88, p.y() - 8, 80, 16)
                                      : QRectF(p.x() + 8, p.y() - 8, 80, 16);
      painter->setPen(QColor(60, 64, 72));
      painter->drawText(
          r, (port->spec().isInput ? Qt::AlignRight : Qt::AlignLeft) | Qt::AlignVCenter, name);
    } else if (port->spec().isInput) {
      painter->drawText(QRectF(p.x() + 9, p.y() - 8, w / 2 - 12, 16),
                        Qt::AlignLeft | Qt::AlignVCenter, name);
    } else {
      painter->drawText(QRectF(p.x() - w / 2 + 3, p.y() - 8, w / 2 - 12, 16),
                        Qt::AlignRight | Qt::AlignVCenter, name);
    }
  }
  painter->setPen(outline);
  painter->setBrush(Qt::NoBrush);
  painter->drawPath(body);

  if (!badge_.isEmpty()) {
    painter->setFont(smallFont);
    const double textWidth = QFontMetricsF(smallFont).horizontalAdvance(badge_) + 10;
    const QRectF r(w - textWidth, -12, textWidth, 14);
    painter->setPen(Qt::NoPen);
    painter->setBrush(QColor(255, 255, 255, 230));
    painter->drawRoundedRect(r, 4, 4);
    painter->setPen(QColor(40, 44, 52));
    painter->drawText(r, Qt::AlignCenter, badge_);
  }
  if (problemLevel_ > 0) {
    const QPointF c(kind_ == NodeKind::Filter ? w / 2 + 22 : w - 4,
                    kind_ == NodeKind::Filter ? 14 : 2);
    painter->setPen(QPen(Qt::white, 1.5));
    painter->setBrush(problemLevel_ >= 2 ? QColor(220, 30, 30) : QColor(240, 170, 0));
    painter->drawEllipse(c, 9, 9);
    QFont bold = smallFont;
    bold.setBold(true);
    bold.setPointSizeF(9);
    painter->setFont(bold);
    painter->drawText(QRectF(c.x() - 9, c.y() - 9, 18, 18), Qt::AlignCenter, "!");
  }
  if (!runInfo_.isEmpty()) {
    painter->setFont(smallFont);
    painter->setPen(failed_ ? QColor(200, 20, 20) : QColor(30, 110, 50));
    painter->drawText(QRectF(-40, h + 4, w + 80, 30),
                      Qt::AlignHCenter | Qt::AlignTop | Qt::TextWordWrap, runInfo_);
  }
}

}  // namespace vrflow::editor::gui
