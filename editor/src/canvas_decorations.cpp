// What the canvas draws over its items after each change: problems, tooltips, composite
// spreads, initial-message tokens and the last run's statistics.
#include <QGraphicsRectItem>
#include <QGraphicsScene>
#include <QGraphicsSimpleTextItem>
#include <QPen>

#include "canvas.hpp"
#include "qt_text.hpp"

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

void Canvas::decorate() {
  const app::Application& app = *state_.app;
  const app::Catalog& catalog = *state_.catalog;
  for (auto* item : decorations_) delete item;
  decorations_.clear();

  // Connections: what they carry, then their problems.
  for (auto* item : connections_) {
    const auto& conn = app.connections[item->index()];
    const PortItem* from = portItem(conn.from.node, conn.from.port);
    const PortItem* to = portItem(conn.to.node, conn.to.port);
    std::string dataType = from != nullptr ? from->spec().data : std::string();
    if (dataType == app::kAnyData && to != nullptr) dataType = to->spec().data;
    item->setToolTip(qtText(app::toString(conn.from) + " \u2192 " + app::toString(conn.to) +
                            "\ndata: " + dataType));
    item->setProblem(0);
    item->setLabel({});
  }
  // Initial messages: tokens on the inputs that have them.
  for (auto& [id, node] : nodes_) {
    for (PortItem* port : node->ports()) port->setTokens(0);
  }
  for (const auto& m : app.modules) {
    for (const auto& input : m.inputs) {
      if (PortItem* port = portItem(m.id, input.port)) port->setTokens(input.initialMessages);
    }
  }

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

  // Instances: how many modules they expand to, and where (from the editor model).
  std::map<std::string, QString> instanceAbout;
  for (const auto& [id, summary] : instanceSummaries(app)) {
    if (auto* item = nodeItem(id)) item->setBadge(qtText(badgeText(summary)));
    QStringList hosts;
    for (const auto& h : summary.hosts) hosts << qtText(h);
    instanceAbout[id] = QString("%1 modules on %2").arg(summary.modules).arg(hosts.join(", "));
  }
  // Tooltips: the problems first, then what the node is.
  for (auto& [id, item] : nodes_) {
    QString about = instanceAbout[id];
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
      item->setProblems(0, about);
    }
    item->setRunInfo({}, false);
  }

  // What the last run reported: totals and averages over its wall time.
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
        // Under the pointer (the tooltip) and in the run table, never piled on the ports.
        item->setLabel(total);
        item->setToolTip(item->toolTip() + "\nlast run: " + total +
                         (wall > 0 ? "\naverage: " + shown : QString()));
      }
    }
  }
  if (!state_.run && !state_.live.empty()) setLiveRates(state_.live);
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
