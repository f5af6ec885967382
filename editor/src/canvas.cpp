#include "canvas.hpp"

#include <QContextMenuEvent>
#include <QGraphicsPathItem>
#include <QGraphicsRectItem>
#include <QGraphicsScene>
#include <QGraphicsSceneHoverEvent>
#include <QGraphicsSimpleTextItem>
#include <QKeyEvent>
#include <QMimeData>
#include <QMouseEvent>
#include <QPainter>
#include <QScrollBar>
#include <QToolTip>
#include <QWheelEvent>
#include <algorithm>
#include <cmath>
#include <set>

#include "vrflow/app/expand.hpp"

namespace vrflow::editor::gui {

namespace {

constexpr double kModuleWidth = 190;
constexpr double kHeader = 42;
constexpr double kRow = 18;
constexpr double kFilterWidth = 130;
constexpr double kPortRadius = 5;
constexpr double kGrid = 10;

QString q(const std::string& text) {
  return QString::fromStdString(text);
}

double snap(double v) {
  return std::round(v / kGrid) * kGrid;
}

QPainterPath curve(QPointF from, QPointF to) {
  QPainterPath path(from);
  if (to.x() < from.x() + 30) {
    // A connection going back (a feedback loop): around, below both ends, not through nodes.
    const double below = std::max(from.y(), to.y()) + 60;
    const double midX = (from.x() + to.x()) / 2;
    path.cubicTo(from + QPointF(70, 0), QPointF(from.x() + 70, below), QPointF(midX, below));
    path.cubicTo(QPointF(to.x() - 70, below), to - QPointF(70, 0), to);
    return path;
  }
  const double dx = std::max(40.0, std::abs(to.x() - from.x()) * 0.5);
  path.cubicTo(from + QPointF(dx, 0), to - QPointF(dx, 0), to);
  return path;
}

QString humanBytes(double bytes) {
  const char* units[] = {"B", "KB", "MB", "GB"};
  int unit = 0;
  while (bytes >= 1024 && unit < 3) {
    bytes /= 1024;
    ++unit;
  }
  return QString::number(bytes, 'f', unit == 0 ? 0 : 1) + " " + units[unit];
}

}  // namespace

QColor colorOfData(const std::string& data) {
  if (data == "any" || data.empty()) return QColor(120, 120, 130);
  if (data == "objects") return QColor(52, 120, 246);
  if (data == "events") return QColor(236, 130, 30);
  if (data == "resources") return QColor(40, 170, 90);
  std::size_t hash = std::hash<std::string>{}(data);
  return QColor::fromHsv(static_cast<int>(hash % 360), 170, 210);
}

QColor colorOfHost(std::size_t index) {
  static const QColor colors[] = {QColor(96, 125, 139), QColor(0, 150, 136), QColor(156, 39, 176),
                                  QColor(233, 30, 99),  QColor(63, 81, 181), QColor(205, 140, 0),
                                  QColor(121, 85, 72),  QColor(76, 175, 80)};
  return colors[index % (sizeof colors / sizeof colors[0])];
}

// ---- PortItem ----------------------------------------------------------------------------

PortItem::PortItem(QGraphicsItem* parent, std::string node, app::PortSpec spec)
    : QGraphicsItem(parent), node_(std::move(node)), spec_(std::move(spec)) {
  setAcceptHoverEvents(true);
  QString tip =
      q(spec_.name) + (spec_.isInput ? " (input)" : " (output)") + "\ndata: " + q(spec_.data);
  if (spec_.stampsOnly) tip += ", stamps only";
  if (spec_.required) tip += "\nrequired";
  if (!spec_.doc.empty()) tip += "\n" + q(spec_.doc);
  setToolTip(tip);
}

QRectF PortItem::boundingRect() const {
  const double r = kPortRadius + 3;
  return {-r, -r, 2 * r, 2 * r};
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
}

// ---- NodeItem ----------------------------------------------------------------------------

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

// ---- ConnectionItem ----------------------------------------------------------------------

ConnectionItem::ConnectionItem(std::size_t index, QPointF from, QPointF to, QColor color,
                               bool stampsOnly)
    : index_(index), path_(curve(from, to)), color_(color), stampsOnly_(stampsOnly) {
  setFlags(ItemIsSelectable);
  setZValue(0);
  mid_ = path_.pointAtPercent(0.5);
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

// ---- Canvas ------------------------------------------------------------------------------

Canvas::Canvas(QWidget* parent) : QGraphicsView(parent), scene_(new QGraphicsScene(this)) {
  setScene(scene_);
  setRenderHints(QPainter::Antialiasing | QPainter::TextAntialiasing);
  setDragMode(QGraphicsView::RubberBandDrag);
  setTransformationAnchor(QGraphicsView::AnchorUnderMouse);
  setViewportUpdateMode(QGraphicsView::FullViewportUpdate);
  setAcceptDrops(true);
  setMouseTracking(true);
  scene_->setSceneRect(-4000, -4000, 8000, 8000);
  connect(scene_, &QGraphicsScene::selectionChanged, this, &Canvas::selectionChangedIds);
}

Canvas::~Canvas() {
  // The scene (a child) is deleted after this object: its last signals must not reach it.
  disconnect(scene_, nullptr, this, nullptr);
}

namespace {
// A small boxed text at `centre`, above the nodes.
QGraphicsRectItem* makeLabel(const QString& text, QPointF centre, QColor border, QColor ink) {
  auto* item = new QGraphicsSimpleTextItem(text);
  QFont font = item->font();
  font.setPointSizeF(7);
  item->setFont(font);
  item->setBrush(ink);
  const QRectF box = item->boundingRect().adjusted(-3, -1, 3, 1);
  auto* back = new QGraphicsRectItem(box);
  back->setBrush(QColor(255, 255, 255, 225));
  back->setPen(QPen(border, 1));
  item->setParentItem(back);
  back->setPos(centre - box.center());
  back->setZValue(3);
  return back;
}
}  // namespace

void Canvas::rebuild() {
  const std::vector<std::string> selected = selectedNodes();
  const std::vector<std::size_t> selectedEdges = selectedConnections();
  {
    const QSignalBlocker block(scene_);
    dragFrom_ = nullptr;
    dragLine_ = nullptr;
    scene_->clear();
  }
  nodes_.clear();
  connections_.clear();
  decorations_.clear();
  if (state_.app == nullptr || state_.catalog == nullptr) return;
  const app::Application& app = *state_.app;
  const app::Catalog& catalog = *state_.catalog;

  std::map<std::string, QColor> hostColor;
  for (std::size_t i = 0; i < app.hosts.size(); ++i) hostColor[app.hosts[i].id] = colorOfHost(i);
  auto colorFor = [&](const std::string& host) {
    const std::string h = app::effectiveHost(app, host);
    auto it = hostColor.find(h);
    return it == hostColor.end() ? QColor(90, 90, 90) : it->second;
  };
  auto place = [&](NodeItem* item) {
    double x = 0, y = 0;
    if (const auto* pos = app::findEditorNode(app, item->id())) {
      x = pos->x;
      y = pos->y;
    } else if (auto it = state_.fallback.find(item->id()); it != state_.fallback.end()) {
      std::tie(x, y) = it->second;
    }
    item->setPos(x, y);
    scene_->addItem(item);
    nodes_[item->id()] = item;
  };
  // A node whose type no installed package declares still shows the ports its connections
  // name, so that the network keeps its shape (validation reports the unknown type).
  auto portsFromConnections = [&](const std::string& id) {
    std::vector<app::PortSpec> ports;
    auto add = [&](const std::string& name, bool input) {
      for (const auto& p : ports) {
        if (p.name == name && p.isInput == input) return;
      }
      app::PortSpec spec;
      spec.name = name;
      spec.isInput = input;
      spec.doc = "declared by no installed package";
      ports.push_back(spec);
    };
    for (const auto& c : app.connections) {
      if (c.to.node == id) add(c.to.port, true);
      if (c.from.node == id) add(c.from.port, false);
    }
    return ports;
  };
  for (const auto& m : app.modules) {
    const auto* type = catalog.findModule(m.package, m.type);
    const QString sub = q(m.package + "/" + m.type) + (type == nullptr ? " (unknown)" : "");
    place(new NodeItem(m.id, NodeKind::Module, q(m.id), sub, colorFor(m.host),
                       q(app::effectiveHost(app, m.host)),
                       type == nullptr ? portsFromConnections(m.id) : catalog.portsOf(m)));
  }
  for (const auto& f : app.filters) {
    const auto* type = catalog.findFilter(f.type);
    place(new NodeItem(f.id, NodeKind::Filter, q(f.id),
                       q(f.type) + (type == nullptr ? " (unknown)" : ""), colorFor(f.host),
                       q(app::effectiveHost(app, f.host)),
                       type == nullptr ? portsFromConnections(f.id) : catalog.portsOf(f)));
  }
  // Instances: how many modules they expand to, and on which hosts.
  std::map<std::string, std::pair<int, std::set<std::string>>> spread;
  if (!app.instances.empty()) {
    auto flat = app::expandComposites(app, app::defaultCompositeSources(app));
    if (flat) {
      for (const auto& m : flat->modules) {
        const auto sep = m.id.find(app::kInstanceSeparator);
        if (sep == std::string::npos) continue;
        auto& entry = spread[m.id.substr(0, sep)];
        ++entry.first;
        entry.second.insert(app::effectiveHost(*flat, m.host));
      }
    }
  }
  for (const auto& i : app.instances) {
    auto* item = new NodeItem(i.id, NodeKind::Instance, q(i.id), "composite " + q(i.composite),
                              colorFor(i.host), q(app::effectiveHost(app, i.host)),
                              nodePorts(app, catalog, i.id));
    if (auto it = spread.find(i.id); it != spread.end()) {
      QStringList hosts;
      for (const auto& h : it->second.second) hosts << q(h);
      item->setBadge(
          QString("%1 modules on %2")
              .arg(it->second.first)
              .arg(hosts.size() <= 2 ? hosts.join(", ") : QString("%1 hosts").arg(hosts.size())));
      item->setToolTip(QString("%1 modules on %2").arg(it->second.first).arg(hosts.join(", ")));
    }
    place(item);
  }

  for (std::size_t c = 0; c < app.connections.size(); ++c) {
    const auto& conn = app.connections[c];
    PortItem* from = portItem(conn.from.node, conn.from.port);
    PortItem* to = portItem(conn.to.node, conn.to.port);
    if (from == nullptr || to == nullptr) continue;  // validation reports it
    std::string dataType = from->spec().data;
    if (dataType == app::kAnyData) dataType = to->spec().data;
    auto* item = new ConnectionItem(c, from->scenePos(), to->scenePos(), colorOfData(dataType),
                                    from->spec().stampsOnly);
    item->setToolTip(
        q(app::toString(conn.from) + " \u2192 " + app::toString(conn.to) + "\ndata: " + dataType));
    scene_->addItem(item);
    connections_.push_back(item);
  }

  // Problems.
  std::map<std::string, std::pair<int, QStringList>> nodeProblems;
  for (const auto& p : state_.problems) {
    const int level = p.severity == app::Diagnostic::Error ? 2 : 1;
    if (!p.cycle.empty()) {
      for (std::size_t c : p.cycle) {
        if (auto* item = connectionItem(c)) {
          item->setProblem(3);
          item->setToolTip(item->toolTip() + "\n" + q(p.message));
          auto* label =
              makeLabel("deadlock", item->midPoint(), QColor(220, 30, 30), QColor(200, 20, 20));
          label->setToolTip(q(p.message));
          scene_->addItem(label);
          decorations_.push_back(label);
        }
      }
      continue;
    }
    if (p.connection) {
      if (auto* item = connectionItem(*p.connection)) {
        item->setProblem(std::max(item->problem(), level));
        item->setToolTip(item->toolTip() + "\n" + q(p.message));
      }
    }
    if (!p.node.empty()) {
      auto& entry = nodeProblems[p.node];
      entry.first = std::max(entry.first, level);
      entry.second << (level == 2 ? "error: " : "warning: ") + q(p.message);
    }
  }
  // Tooltips: the problems first, then what the node is.
  for (auto& [id, item] : nodes_) {
    QString about = item->toolTip();  // instances: how many modules, where
    if (const auto* m = app::findModule(app, id)) {
      const auto* type = catalog.findModule(m->package, m->type);
      about = q(m->id + ": module " + m->package + "/" + m->type + " on " +
                app::effectiveHost(app, m->host)) +
              (type != nullptr && !type->doc.empty() ? "\n" + q(type->doc) : QString());
    } else if (const auto* f = app::findFilter(app, id)) {
      const auto* type = catalog.findFilter(f->type);
      about = q(f->id + ": filter " + f->type + " on " + app::effectiveHost(app, f->host)) +
              (type != nullptr && !type->doc.empty() ? "\n" + q(type->doc) : QString());
    }
    if (auto it = nodeProblems.find(id); it != nodeProblems.end()) {
      item->setProblems(it->second.first, it->second.second.join("\n") + "\n\n" + about);
    } else {
      item->setToolTip(about);
    }
  }

  // What the last run reported: totals and averages over its wall time (the runtime reports no
  // live per-connection rates).
  if (state_.run) {
    const RunReport& run = *state_.run;
    const double wall = run.wallSeconds > 0 ? run.wallSeconds : 0;
    for (auto& [id, item] : nodes_) {
      auto it = run.modules.find(id);
      const bool failed = run.failedModule == id;
      if (it == run.modules.end()) {
        if (failed) item->setRunInfo("failed", true);
        continue;
      }
      QString text = QString("%1 it").arg(it->second.iterations);
      if (wall > 0)
        text += QString(" \u00b7 %1 it/s")
                    .arg(static_cast<double>(it->second.iterations) / wall, 0, 'f', 1);
      if (failed) text += "\nfailed: " + q(it->second.exit);
      item->setRunInfo(text, failed);
    }
    for (const auto& stats : run.connections) {
      for (auto* item : connections_) {
        const auto& conn = app.connections[item->index()];
        if (app::toString(conn.from) != stats.from || app::toString(conn.to) != stats.to) continue;
        QString total = QString("%1 msg, %2")
                            .arg(stats.messages)
                            .arg(humanBytes(static_cast<double>(stats.bytes)));
        if (stats.dropped > 0) total += QString(", %1 dropped").arg(stats.dropped);
        // On the canvas: the averages over the run; the totals in the tooltip.
        QString shown = total;
        if (wall > 0) {
          shown = QString("%1 msg/s \u00b7 %2/s")
                      .arg(static_cast<double>(stats.messages) / wall, 0, 'f', 0)
                      .arg(humanBytes(static_cast<double>(stats.bytes) / wall));
        }
        item->setLabel(total);
        item->setToolTip(item->toolTip() + "\nlast run: " + total +
                         (wall > 0 ? "\naverage: " + shown : QString()));
        auto* back = makeLabel(shown, item->midPoint(), item->color(), QColor(30, 60, 120));
        back->setToolTip(item->toolTip());
        scene_->addItem(back);
        decorations_.push_back(back);
      }
    }
  }

  if (!state_.run && !state_.live.empty()) setLiveRates(state_.live);

  const QSignalBlocker block(scene_);
  for (const auto& id : selected) {
    if (auto* item = nodeItem(id)) item->setSelected(true);
  }
  for (std::size_t c : selectedEdges) {
    if (auto* item = connectionItem(c)) item->setSelected(true);
  }
}

void Canvas::setLiveRates(const std::map<std::string, double>& rates) {
  state_.live = rates;
  for (auto& [id, item] : nodes_) {
    auto it = rates.find(id);
    if (it != rates.end())
      item->setRunInfo(QString("running \u00b7 %1 it/s").arg(it->second, 0, 'f', 0), false);
  }
}

std::vector<std::string> Canvas::selectedNodes() const {
  std::vector<std::string> ids;
  if (state_.app == nullptr) return ids;
  for (const auto& id : nodeIds(*state_.app)) {
    auto it = nodes_.find(id);
    if (it != nodes_.end() && it->second->isSelected()) ids.push_back(id);
  }
  return ids;
}

std::vector<std::size_t> Canvas::selectedConnections() const {
  std::vector<std::size_t> result;
  for (const auto* item : connections_) {
    if (item->isSelected()) result.push_back(item->index());
  }
  return result;
}

void Canvas::selectOnly(const std::vector<std::string>& ids,
                        std::optional<std::size_t> connection) {
  {
    const QSignalBlocker block(scene_);
    scene_->clearSelection();
    for (const auto& id : ids) {
      if (auto* item = nodeItem(id)) item->setSelected(true);
    }
    if (connection) {
      if (auto* item = connectionItem(*connection)) item->setSelected(true);
    }
  }
  if (!ids.empty()) {
    if (auto* item = nodeItem(ids.front())) ensureVisible(item, 80, 80);
  } else if (connection) {
    if (auto* item = connectionItem(*connection)) ensureVisible(item, 80, 80);
  }
  Q_EMIT selectionChangedIds();
}

NodeItem* Canvas::nodeItem(const std::string& id) const {
  auto it = nodes_.find(id);
  return it == nodes_.end() ? nullptr : it->second;
}

PortItem* Canvas::portItem(const std::string& node, const std::string& port) const {
  NodeItem* item = nodeItem(node);
  if (item == nullptr) return nullptr;
  for (PortItem* p : item->ports()) {
    if (p->spec().name == port) return p;
  }
  return nullptr;
}

ConnectionItem* Canvas::connectionItem(std::size_t index) const {
  for (auto* item : connections_) {
    if (item->index() == index) return item;
  }
  return nullptr;
}

QPointF Canvas::portScenePos(const std::string& node, const std::string& port) const {
  const PortItem* item = portItem(node, port);
  return item == nullptr ? QPointF() : item->scenePos();
}

void Canvas::fitAll() {
  QRectF bounds;
  for (const auto& [id, item] : nodes_) bounds = bounds.united(item->sceneBoundingRect());
  for (const auto* item : connections_) bounds = bounds.united(item->sceneBoundingRect());
  if (bounds.isEmpty()) {
    resetTransform();
    centerOn(0, 0);
    return;
  }
  fitInView(bounds.adjusted(-30, -30, 30, 30), Qt::KeepAspectRatio);
  // Do not blow small networks up beyond their natural size, nor shrink big ones until their
  // text cannot be read (scroll instead).
  if (transform().m11() > 1.0 || transform().m11() < 0.5) {
    const double scale = transform().m11() > 1.0 ? 1.0 : 0.5;
    setTransform(QTransform::fromScale(scale, scale));
    centerOn(bounds.center());
  }
}

Positions Canvas::nodeSizes() const {
  Positions sizes;
  for (const auto& [id, item] : nodes_) {
    // Room for the labels around rhombi and the run text under nodes.
    const double extra = item->kind() == NodeKind::Filter ? 70 : 0;
    sizes[id] = {item->size().width() + extra, item->size().height() + 30};
  }
  return sizes;
}

std::optional<std::string> Canvas::refusalBetween(const PortItem* from, const PortItem* to) const {
  if (from == nullptr || to == nullptr || state_.app == nullptr)
    return std::string("no port there");
  if (from == to) return std::string("a port cannot be connected to itself");
  // Dragging may start at either end: the output is the source.
  const PortItem* out = from->spec().isInput ? to : from;
  const PortItem* in = from->spec().isInput ? from : to;
  if (out->spec().isInput == in->spec().isInput) {
    return std::string(out->spec().isInput
                           ? "both ports are inputs: connect an output to an input"
                           : "both ports are outputs: connect an output to an input");
  }
  return connectionRefusal(*state_.app, *state_.catalog, out->endpoint(), in->endpoint());
}

QPointF Canvas::dropPoint() const {
  return mapToScene(viewport()->rect().center());
}

PortItem* Canvas::portAt(QPoint viewPos) const {
  const QPointF scenePos = mapToScene(viewPos);
  PortItem* best = nullptr;
  double bestDistance = 12.0 / std::max(0.2, transform().m11());
  for (const auto& [id, node] : nodes_) {
    for (PortItem* port : node->ports()) {
      const double d = QLineF(port->scenePos(), scenePos).length();
      if (d <= bestDistance) {
        bestDistance = d;
        best = port;
      }
    }
  }
  return best;
}

NodeItem* Canvas::nodeAt(QPoint viewPos) const {
  for (QGraphicsItem* item : items(viewPos)) {
    if (auto* node = dynamic_cast<NodeItem*>(item)) {
      if (node->shape().contains(node->mapFromScene(mapToScene(viewPos)))) return node;
    }
  }
  return nullptr;
}

void Canvas::mousePressEvent(QMouseEvent* event) {
  if (event->button() == Qt::MiddleButton) {
    panning_ = true;
    panLast_ = event->position().toPoint();
    setCursor(Qt::ClosedHandCursor);
    event->accept();
    return;
  }
  if (event->button() == Qt::LeftButton) {
    if (PortItem* port = portAt(event->position().toPoint())) {
      dragFrom_ = port;
      dragLine_ = new QGraphicsPathItem;
      dragLine_->setPen(QPen(colorOfData(port->spec().data), 2, Qt::DashLine));
      dragLine_->setZValue(5);
      scene_->addItem(dragLine_);
      event->accept();
      return;
    }
  }
  QGraphicsView::mousePressEvent(event);
}

void Canvas::mouseMoveEvent(QMouseEvent* event) {
  if (panning_) {
    const QPoint delta = event->position().toPoint() - panLast_;
    panLast_ = event->position().toPoint();
    horizontalScrollBar()->setValue(horizontalScrollBar()->value() - delta.x());
    verticalScrollBar()->setValue(verticalScrollBar()->value() - delta.y());
    event->accept();
    return;
  }
  if (dragFrom_ != nullptr) {
    const QPointF start = dragFrom_->scenePos();
    const QPointF end = mapToScene(event->position().toPoint());
    dragLine_->setPath(dragFrom_->spec().isInput ? curve(end, start) : curve(start, end));
    for (const auto& [id, node] : nodes_) {
      for (PortItem* port : node->ports()) port->setHighlight(0);
    }
    if (PortItem* target = portAt(event->position().toPoint());
        target != nullptr && target != dragFrom_) {
      const auto why = refusalBetween(dragFrom_, target);
      target->setHighlight(why ? -1 : 1);
      if (why) {
        QToolTip::showText(event->globalPosition().toPoint(), QString::fromStdString(*why),
                           viewport());
      } else {
        QToolTip::hideText();
      }
    }
    event->accept();
    return;
  }
  QGraphicsView::mouseMoveEvent(event);
}

void Canvas::mouseReleaseEvent(QMouseEvent* event) {
  if (panning_ && event->button() == Qt::MiddleButton) {
    panning_ = false;
    unsetCursor();
    event->accept();
    return;
  }
  if (dragFrom_ != nullptr && event->button() == Qt::LeftButton) {
    PortItem* from = dragFrom_;
    dragFrom_ = nullptr;
    delete dragLine_;
    dragLine_ = nullptr;
    for (const auto& [id, node] : nodes_) {
      for (PortItem* port : node->ports()) port->setHighlight(0);
    }
    PortItem* target = portAt(event->position().toPoint());
    if (target != nullptr && target != from) {
      if (const auto why = refusalBetween(from, target)) {
        lastRefusal_ = QString::fromStdString(*why);
        QToolTip::showText(event->globalPosition().toPoint(), lastRefusal_, viewport());
      } else {
        lastRefusal_.clear();
        const PortItem* out = from->spec().isInput ? target : from;
        const PortItem* in = from->spec().isInput ? from : target;
        Q_EMIT connectRequested(out->endpoint(), in->endpoint());
      }
    }
    event->accept();
    return;
  }
  QGraphicsView::mouseReleaseEvent(event);
  if (event->button() != Qt::LeftButton || state_.app == nullptr) return;
  // Nodes dragged to a new place: snap to the grid and report where.
  Positions moved;
  for (const auto& [id, item] : nodes_) {
    if (!item->isSelected()) continue;
    const QPointF pos(snap(item->pos().x()), snap(item->pos().y()));
    const auto* saved = app::findEditorNode(*state_.app, id);
    double x0 = 0, y0 = 0;
    if (saved != nullptr) {
      x0 = saved->x;
      y0 = saved->y;
    } else if (auto it = state_.fallback.find(id); it != state_.fallback.end()) {
      std::tie(x0, y0) = it->second;
    }
    if (std::abs(item->pos().x() - x0) > 0.5 || std::abs(item->pos().y() - y0) > 0.5) {
      moved[id] = {pos.x(), pos.y()};
    }
  }
  if (!moved.empty()) Q_EMIT nodesMoved(moved);
}

void Canvas::wheelEvent(QWheelEvent* event) {
  const double factor = std::pow(1.0015, event->angleDelta().y());
  const double scale = transform().m11() * factor;
  if (scale < 0.1 || scale > 4) return;
  this->scale(factor, factor);
  event->accept();
}

void Canvas::keyPressEvent(QKeyEvent* event) {
  if (event->key() == Qt::Key_Delete || event->key() == Qt::Key_Backspace) {
    Q_EMIT deleteRequested();
    event->accept();
    return;
  }
  QGraphicsView::keyPressEvent(event);
}

void Canvas::contextMenuEvent(QContextMenuEvent* event) {
  NodeItem* node = nodeAt(event->pos());
  if (node == nullptr) return;
  if (!node->isSelected()) selectOnly({node->id()});
  Q_EMIT contextMenuForNodes(selectedNodes(), event->globalPos());
}

namespace {
// Drops are always copies: a move would make the palette or the hosts table drop the row.
void acceptAsCopy(QDropEvent* event) {
  event->setDropAction(Qt::CopyAction);
  event->accept();
}
}  // namespace

void Canvas::dragEnterEvent(QDragEnterEvent* event) {
  if (event->mimeData()->hasFormat(kNodeMime) || event->mimeData()->hasFormat(kHostMime)) {
    acceptAsCopy(event);
  }
}

void Canvas::dragMoveEvent(QDragMoveEvent* event) {
  if (event->mimeData()->hasFormat(kNodeMime)) {
    acceptAsCopy(event);
  } else if (event->mimeData()->hasFormat(kHostMime)) {
    if (nodeAt(event->position().toPoint()) != nullptr) {
      acceptAsCopy(event);
    } else {
      event->ignore();
    }
  }
}

void Canvas::dropEvent(QDropEvent* event) {
  const QMimeData* mime = event->mimeData();
  if (mime->hasFormat(kNodeMime)) {
    const QPointF at = mapToScene(event->position().toPoint());
    Q_EMIT addRequested(QString::fromUtf8(mime->data(kNodeMime)),
                        QPointF(snap(at.x()), snap(at.y())));
    acceptAsCopy(event);
  } else if (mime->hasFormat(kHostMime)) {
    if (NodeItem* node = nodeAt(event->position().toPoint())) {
      Q_EMIT hostDropped(QString::fromUtf8(mime->data(kHostMime)), node->id());
      acceptAsCopy(event);
    }
  }
}

void Canvas::drawBackground(QPainter* painter, const QRectF& rect) {
  painter->fillRect(rect, QColor(236, 238, 242));
  const double step = 20;
  QPen minor(QColor(222, 225, 231), 0);
  painter->setPen(minor);
  const double left = std::floor(rect.left() / step) * step;
  const double top = std::floor(rect.top() / step) * step;
  if (transform().m11() < 0.4) return;
  QVector<QLineF> lines;
  for (double x = left; x < rect.right(); x += step)
    lines.append(QLineF(x, rect.top(), x, rect.bottom()));
  for (double y = top; y < rect.bottom(); y += step)
    lines.append(QLineF(rect.left(), y, rect.right(), y));
  painter->drawLines(lines);
}

}  // namespace vrflow::editor::gui
