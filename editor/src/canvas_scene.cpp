// The canvas' scene: one item per node and connection of the application, placed where the file
// (or the automatic layout) puts them, with problems, composite spreads and the run's statistics
// drawn over them.
#include <QGraphicsRectItem>
#include <QGraphicsScene>
#include <QGraphicsSimpleTextItem>
#include <QPen>
#include <set>

#include "canvas.hpp"
#include "qt_text.hpp"
#include "vrflow/app/expand.hpp"

namespace vrflow::editor::gui {

namespace {

QString humanBytes(double bytes) {
  const char* units[] = {"B", "KB", "MB", "GB"};
  int unit = 0;
  while (bytes >= 1024 && unit < 3) {
    bytes /= 1024;
    ++unit;
  }
  return QString::number(bytes, 'f', unit == 0 ? 0 : 1) + " " + units[unit];
}

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
    const QString sub = qtText(m.package + "/" + m.type) + (type == nullptr ? " (unknown)" : "");
    place(new NodeItem(m.id, NodeKind::Module, qtText(m.id), sub, colorFor(m.host),
                       qtText(app::effectiveHost(app, m.host)),
                       type == nullptr ? portsFromConnections(m.id) : catalog.portsOf(m)));
  }
  for (const auto& f : app.filters) {
    const auto* type = catalog.findFilter(f.type);
    place(new NodeItem(f.id, NodeKind::Filter, qtText(f.id),
                       qtText(f.type) + (type == nullptr ? " (unknown)" : ""), colorFor(f.host),
                       qtText(app::effectiveHost(app, f.host)),
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
    auto* item = new NodeItem(
        i.id, NodeKind::Instance, qtText(i.id), "composite " + qtText(i.composite),
        colorFor(i.host), qtText(app::effectiveHost(app, i.host)), nodePorts(app, catalog, i.id));
    if (auto it = spread.find(i.id); it != spread.end()) {
      QStringList hosts;
      for (const auto& h : it->second.second) hosts << qtText(h);
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
    item->setToolTip(qtText(app::toString(conn.from) + " \u2192 " + app::toString(conn.to) +
                            "\ndata: " + dataType));
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
          item->setToolTip(item->toolTip() + "\n" + qtText(p.message));
          auto* label =
              makeLabel("deadlock", item->midPoint(), QColor(220, 30, 30), QColor(200, 20, 20));
          label->setToolTip(qtText(p.message));
          scene_->addItem(label);
          decorations_.push_back(label);
        }
      }
      continue;
    }
    if (p.connection) {
      if (auto* item = connectionItem(*p.connection)) {
        item->setProblem(std::max(item->problem(), level));
        item->setToolTip(item->toolTip() + "\n" + qtText(p.message));
      }
    }
    if (!p.node.empty()) {
      auto& entry = nodeProblems[p.node];
      entry.first = std::max(entry.first, level);
      entry.second << (level == 2 ? "error: " : "warning: ") + qtText(p.message);
    }
  }
  // Tooltips: the problems first, then what the node is.
  for (auto& [id, item] : nodes_) {
    QString about = item->toolTip();  // instances: how many modules, where
    if (const auto* m = app::findModule(app, id)) {
      const auto* type = catalog.findModule(m->package, m->type);
      about = qtText(m->id + ": module " + m->package + "/" + m->type + " on " +
                     app::effectiveHost(app, m->host)) +
              (type != nullptr && !type->doc.empty() ? "\n" + qtText(type->doc) : QString());
    } else if (const auto* f = app::findFilter(app, id)) {
      const auto* type = catalog.findFilter(f->type);
      about = qtText(f->id + ": filter " + f->type + " on " + app::effectiveHost(app, f->host)) +
              (type != nullptr && !type->doc.empty() ? "\n" + qtText(type->doc) : QString());
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
      if (failed) text += "\nfailed: " + qtText(it->second.exit);
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

}  // namespace vrflow::editor::gui
