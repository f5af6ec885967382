#include "live_overlay.hpp"

#include <QGraphicsScene>
#include <QTimer>
#include <algorithm>
#include <set>

#include "canvas.hpp"
#include "qt_text.hpp"
#include "vrflow/app/composite.hpp"

namespace vrflow::editor::gui {

namespace {

// "node.port" split at its last dot.
std::pair<std::string, std::string> splitEndpoint(const std::string& endpoint) {
  const auto dot = endpoint.rfind('.');
  if (dot == std::string::npos) return {endpoint, {}};
  return {endpoint.substr(0, dot), endpoint.substr(dot + 1)};
}

QString mib(double value) {
  return QString::number(value, 'f', value < 10 ? 2 : 1) + " MiB";
}

QString rateText(double messagesPerSecond, double mibPerSecond) {
  return QString("%1 msg/s \u00b7 %2/s").arg(messagesPerSecond, 0, 'f', 0).arg(mib(mibPerSecond));
}

// Deletes the items of `items` whose key `keep` no longer has.
template <typename Map, typename Keep>
void dropMissing(Map& items, const Keep& keep) {
  std::erase_if(items, [&](auto& entry) {
    if (keep.count(entry.first) != 0) return false;
    delete entry.second.data();
    return true;
  });
}

}  // namespace

std::string canvasNodeOf(const Canvas& canvas, const std::string& module) {
  if (canvas.nodeItem(module) != nullptr) return module;
  const auto sep = module.find(app::kInstanceSeparator);
  if (sep != std::string::npos && canvas.nodeItem(module.substr(0, sep)) != nullptr)
    return module.substr(0, sep);
  return {};
}

LiveOverlay::LiveOverlay(Canvas* canvas, LiveRunModel* model, QObject* parent)
    : QObject(parent), canvas_(canvas), model_(model) {
  connect(model, &LiveRunModel::changed, this, &LiveOverlay::refresh);
  // A canvas rebuild deletes our items with its own: make them again once it is done.
  connect(canvas->scene(), &QGraphicsScene::changed, this, &LiveOverlay::sceneChanged);
}

void LiveOverlay::sceneChanged() {
  if (pending_ || canvas_ == nullptr || model_ == nullptr) return;
  if (model_->run().phase == LiveRun::Phase::None) return;
  bool lost = false;
  for (const auto& [id, badge] : badges_)
    lost = lost || badge.isNull() || badge->parentItem() != canvas_->nodeItem(id);
  for (const auto& [index, load] : loads_)
    lost = lost || load.isNull() || load->parentItem() != canvas_->connectionItem(index);
  for (const auto& [pair, link] : links_) lost = lost || link.isNull();
  if (!lost && !badges_.empty()) return;
  pending_ = true;
  QTimer::singleShot(0, this, [this] {
    pending_ = false;
    refresh();
  });
}

ModuleBadgeItem* LiveOverlay::badge(const std::string& node) const {
  const auto it = badges_.find(node);
  return it == badges_.end() ? nullptr : it->second.data();
}

ConnectionLoadItem* LiveOverlay::connectionLoad(std::size_t index) const {
  const auto it = loads_.find(index);
  return it == loads_.end() ? nullptr : it->second.data();
}

std::vector<LinkItem*> LiveOverlay::links() const {
  std::vector<LinkItem*> out;
  for (const auto& [pair, link] : links_) {
    if (!link.isNull()) out.push_back(link.data());
  }
  return out;
}

void LiveOverlay::clear() {
  for (auto& [id, badge] : badges_) delete badge.data();
  for (auto& [index, load] : loads_) delete load.data();
  for (auto& [pair, link] : links_) delete link.data();
  badges_.clear();
  loads_.clear();
  links_.clear();
}

void LiveOverlay::refresh() {
  if (canvas_ == nullptr || model_ == nullptr) return;
  const LiveRun& run = model_->run();
  if (run.phase == LiveRun::Phase::None || canvas_->state().app == nullptr) {
    clear();
    return;
  }
  refreshModules(run);
  refreshConnections(run);
  refreshLinks(run);
}

void LiveOverlay::refreshModules(const LiveRun& run) {
  // Per canvas node: its module's figures, or the sum over an instance's modules.
  std::map<std::string, BadgeFigures> figures;
  std::map<std::string, std::set<std::string>> states;
  for (const auto& [id, module] : run.modules) {
    const std::string node = canvasNodeOf(*canvas_, id);
    if (node.empty()) continue;
    const bool first = figures.count(node) == 0;
    BadgeFigures& f = figures[node];
    f.modules = first ? 1 : f.modules + 1;
    f.rate += module.rate;
    f.cpu += module.cpu;
    f.rssMiB += module.rssMiB;
    f.iterations += module.iterations;
    f.waitShare += (module.waitShare - f.waitShare) / f.modules;  // the mean
    states[node].insert(module.state);
    // Histories summed, aligned on their last entries.
    if (f.history.size() < module.history.size())
      f.history.insert(f.history.begin(), module.history.size() - f.history.size(), 0.0);
    const std::size_t offset = f.history.size() - module.history.size();
    for (std::size_t i = 0; i < module.history.size(); ++i)
      f.history[offset + i] += module.history[i];
    QString failure = qtText(module.failure);
    if (const HostLive* host = run.host(module.host); host != nullptr && !host->cause.empty())
      failure = qtText(host->lost ? "host '" + host->id + "' lost: " + host->cause : host->cause);
    if (failure.isEmpty() && !module.exit.empty() && module.exit != "status 0")
      failure = qtText("exited with " + module.exit);
    if (!failure.isEmpty() && f.failure.isEmpty())
      f.failure = f.modules > 1 || id != node ? qtText(id) + ": " + failure : failure;
  }
  dropMissing(badges_, figures);
  for (auto& [node, f] : figures) {
    const auto& s = states[node];
    f.state = s.size() == 1 ? qtText(*s.begin()) : QString("%1 states").arg(s.size());
    NodeItem* item = canvas_->nodeItem(node);
    QPointer<ModuleBadgeItem>& badge = badges_[node];
    if (badge.isNull() || badge->parentItem() != item) {
      delete badge.data();
      badge = new ModuleBadgeItem(item, item->size());
    }
    badge->setFigures(f);
    // After the run, the canvas shows the report's totals under the nodes: only failures stay.
    badge->setVisible(run.phase == LiveRun::Phase::Running || badge->failed());
  }
}

void LiveOverlay::refreshConnections(const LiveRun& run) {
  const app::Application& app = *canvas_->state().app;
  for (std::size_t c = 0; c < app.connections.size(); ++c) {
    ConnectionItem* item = canvas_->connectionItem(c);
    if (item == nullptr) continue;
    const app::Connection& conn = app.connections[c];
    // The expanded network's connections this canvas connection stands for: the same ends, or
    // any port inside an instance the end belongs to.
    double fill = -1, messagesPerSecond = 0, mibPerSecond = 0;
    uint64_t length = 0, capacity = 0, messages = 0, bytes = 0, dropped = 0;
    int matched = 0;
    for (const auto& live : run.connections) {
      const auto [fromModule, fromPort] = splitEndpoint(live.from);
      const auto [toModule, toPort] = splitEndpoint(live.to);
      const std::string fromNode = canvasNodeOf(*canvas_, fromModule);
      const std::string toNode = canvasNodeOf(*canvas_, toModule);
      if (fromNode != conn.from.node || toNode != conn.to.node) continue;
      if (fromNode == fromModule && fromPort != conn.from.port) continue;
      if (toNode == toModule && toPort != conn.to.port) continue;
      ++matched;
      if (live.capacity > 0) fill = std::max(fill, live.fill);
      length += live.length;
      capacity += live.capacity;
      messagesPerSecond += live.messagesPerSecond;
      mibPerSecond += live.mibPerSecond;
      messages += live.messages;
      bytes += live.bytes;
      dropped += live.dropped;
    }
    QPointer<ConnectionLoadItem>& load = loads_[c];
    if (matched == 0) {
      delete load.data();
      loads_.erase(c);
      continue;
    }
    if (load.isNull() || load->parentItem() != item) {
      delete load.data();
      load = new ConnectionLoadItem(item, item->shape(), item->midPoint());
    }
    QString tooltip = qtText(app::toString(conn.from) + " \u2192 " + app::toString(conn.to));
    tooltip += capacity > 0 ? QString("\nqueue %1 of %2 (%3% full)")
                                  .arg(length)
                                  .arg(capacity)
                                  .arg(fill * 100, 0, 'f', 0)
                            : QString("\nqueue %1 (unbounded)").arg(length);
    tooltip += "\n" + rateText(messagesPerSecond, mibPerSecond);
    tooltip += QString("\ntotal %1 messages, %2")
                   .arg(messages)
                   .arg(mib(static_cast<double>(bytes) / 1048576.0));
    if (dropped > 0) tooltip += QString(", %1 dropped").arg(dropped);
    const bool running = run.phase == LiveRun::Phase::Running;
    load->setLoad(fill, running ? rateText(messagesPerSecond, mibPerSecond) : QString(), tooltip);
    load->setVisible(running);
  }
}

void LiveOverlay::refreshLinks(const LiveRun& run) {
  const app::Application& app = *canvas_->state().app;
  // The hosts' groups: the union of their nodes' bodies.
  std::map<std::string, QRectF> groups;
  for (const auto& [id, module] : run.modules) {
    const std::string node = canvasNodeOf(*canvas_, id);
    if (node.empty()) continue;
    NodeItem* item = canvas_->nodeItem(node);
    const QRectF body = item->mapRectToScene(QRectF(QPointF(0, 0), item->size()));
    QRectF& group = groups[module.host];
    group = group.isNull() ? body : group.united(body);
  }
  std::map<std::pair<std::string, std::string>, QStringList> lines;
  const bool running = run.phase == LiveRun::Phase::Running;
  for (const auto& link : run.links) {
    if (link.messages == 0 && link.bytes == 0) continue;
    const auto key = std::minmax(link.from, link.to);
    QString text = qtText(link.from + " \u2192 " + link.to + ": ");
    text += running ? rateText(link.messagesPerSecond, link.mibPerSecond)
                    : QString("%1 messages, %2")
                          .arg(link.messages)
                          .arg(mib(static_cast<double>(link.bytes) / 1048576.0));
    lines[{key.first, key.second}] << text;
  }
  dropMissing(links_, lines);
  const auto colorOf = [&](const std::string& host) {
    for (std::size_t i = 0; i < app.hosts.size(); ++i) {
      if (app.hosts[i].id == host) return colorOfHost(i);
    }
    return QColor(90, 90, 90);
  };
  for (auto& [pair, text] : lines) {
    if (groups.count(pair.first) == 0 || groups.count(pair.second) == 0) continue;
    text.sort();
    QPointer<LinkItem>& item = links_[pair];
    if (item.isNull()) {
      item = new LinkItem(qtText(pair.first), qtText(pair.second));
      canvas_->scene()->addItem(item);
    }
    item->place(groups[pair.first], groups[pair.second], colorOf(pair.first), colorOf(pair.second));
    const HostLive* a = run.host(pair.first);
    const HostLive* b = run.host(pair.second);
    item->setRates(text, (a != nullptr && a->lost) || (b != nullptr && b->lost));
    // The totals after the run show under the pointer, never piled on the nodes.
    item->setLabelOnHover(run.phase == LiveRun::Phase::Ended);
  }
}

}  // namespace vrflow::editor::gui
