// The canvas' scene: one item per node and connection of the application, placed where the file
// (or the automatic layout) puts them, kept up to date by what each edit changed, with problems,
// composite spreads, initial-message tokens and the run's statistics drawn over them.
#include <QGraphicsScene>
#include <set>

#include "canvas.hpp"
#include "qt_text.hpp"

namespace vrflow::editor::gui {

namespace {

// A node whose type no installed package declares still shows the ports its connections name,
// so that the network keeps its shape (validation reports the unknown type).
std::vector<app::PortSpec> portsFromConnections(const app::Application& app,
                                                const std::string& id) {
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
}

// What a node item is made from; items are remade only when this differs.
struct NodeLook {
  NodeKind kind = NodeKind::None;
  QString title, subtitle, hostName;
  QColor hostColor;
  std::vector<app::PortSpec> ports;

  QString key() const {
    QString k = QString("%1|%2|%3|%4|%5")
                    .arg(static_cast<int>(kind))
                    .arg(title, subtitle, hostName, hostColor.name());
    for (const auto& p : ports) {
      k += QString("|%1%2:%3%4")
               .arg(p.isInput ? "<" : ">", qtText(p.name), qtText(p.data), p.stampsOnly ? "s" : "");
    }
    return k;
  }
};

NodeLook lookOf(const app::Application& app, const app::Catalog& catalog, const std::string& id) {
  NodeLook look;
  look.kind = nodeKind(app, id);
  look.title = qtText(id);
  std::string host;
  if (const auto* m = app::findModule(app, id)) {
    const auto* type = catalog.findModule(m->package, m->type);
    look.subtitle = qtText(m->package + "/" + m->type) + (type == nullptr ? " (unknown)" : "");
    look.ports = type == nullptr ? portsFromConnections(app, id) : catalog.portsOf(*m);
    host = m->host;
  } else if (const auto* f = app::findFilter(app, id)) {
    const auto* type = catalog.findFilter(f->type);
    look.subtitle = qtText(f->type) + (type == nullptr ? " (unknown)" : "");
    look.ports = type == nullptr ? portsFromConnections(app, id) : catalog.portsOf(*f);
    host = f->host;
  } else {
    for (const auto& i : app.instances) {
      if (i.id != id) continue;
      look.subtitle = "composite " + qtText(i.composite);
      look.ports = nodePorts(app, catalog, id);
      host = i.host;
    }
  }
  const std::string effective = app::effectiveHost(app, host);
  look.hostName = qtText(effective);
  look.hostColor = QColor(90, 90, 90);
  for (std::size_t i = 0; i < app.hosts.size(); ++i) {
    if (app.hosts[i].id == effective) look.hostColor = colorOfHost(i);
  }
  return look;
}

}  // namespace

void Canvas::rebuild() {
  const std::vector<std::string> selected = selectedNodes();
  {
    const QSignalBlocker block(scene_);
    dragFrom_ = nullptr;
    dragLine_ = nullptr;
    scene_->clear();
  }
  nodes_.clear();
  looks_.clear();
  connections_.clear();
  notes_.clear();
  frames_.clear();
  decorations_.clear();
  shown_.reset();
  sync();
  const QSignalBlocker block(scene_);
  for (const auto& id : selected) {
    if (auto* item = nodeItem(id)) item->setSelected(true);
  }
}

NodeItem* Canvas::makeNode(const std::string& id) {
  NodeLook look = lookOf(*state_.app, *state_.catalog, id);
  looks_[id] = look.key();
  return new NodeItem(id, look.kind, look.title, look.subtitle, look.hostColor, look.hostName,
                      look.ports);
}

void Canvas::placeNode(NodeItem* item) {
  double x = 0, y = 0;
  if (const auto* pos = app::findEditorNode(*state_.app, item->id())) {
    x = pos->x;
    y = pos->y;
  } else if (auto it = state_.fallback.find(item->id()); it != state_.fallback.end()) {
    std::tie(x, y) = it->second;
  }
  if (item->pos() != QPointF(x, y)) item->setPos(x, y);
  if (item->scene() == nullptr) scene_->addItem(item);
  nodes_[item->id()] = item;
}

void Canvas::removeNode(const std::string& id) {
  auto it = nodes_.find(id);
  if (it == nodes_.end()) return;
  if (dragFrom_ != nullptr && dragFrom_->node() == id) {
    dragFrom_ = nullptr;
    delete dragLine_;
    dragLine_ = nullptr;
  }
  delete it->second;
  nodes_.erase(it);
  looks_.erase(id);
}

void Canvas::sync() {
  if (state_.app == nullptr || state_.catalog == nullptr) return;
  const app::Application& app = *state_.app;
  const Changes changes = diff(shown_ ? *shown_ : app::Application{}, app);
  const QSignalBlocker block(scene_);  // one selectionChanged at most, below

  std::set<std::string> remade;
  for (const auto& id : changes.nodesRemoved) removeNode(id);
  // Changed nodes (and every node when the hosts changed: their colours) are remade only when
  // what the item draws differs; the others keep their item.
  std::vector<std::string> recheck = changes.nodesChanged;
  if (changes.hostsChanged) recheck = nodeIds(app);
  for (const auto& id : recheck) {
    auto it = nodes_.find(id);
    if (it == nodes_.end() || lookOf(app, *state_.catalog, id).key() == looks_[id]) continue;
    const bool selected = it->second->isSelected();
    removeNode(id);
    NodeItem* item = makeNode(id);
    placeNode(item);
    item->setSelected(selected);
    remade.insert(id);
  }
  for (const auto& id : changes.nodesAdded) {
    placeNode(makeNode(id));
    remade.insert(id);
  }
  for (const auto& id : changes.nodesMoved) {
    if (auto* item = nodeItem(id)) placeNode(item);
  }
  // Nodes the file places nowhere follow the automatic layout.
  for (auto& [id, item] : nodes_) {
    if (app::findEditorNode(app, id) == nullptr) placeNode(item);
  }

  // Connections: kept by their ends, remade when an end node was remade.
  std::map<std::string, std::vector<ConnectionItem*>> kept;
  for (auto* item : connections_) {
    const std::string key = shown_ && item->index() < shown_->connections.size()
                                ? connectionKey(shown_->connections[item->index()])
                                : std::string();
    kept[key].push_back(item);
  }
  std::vector<ConnectionItem*> now;
  for (std::size_t c = 0; c < app.connections.size(); ++c) {
    const auto& conn = app.connections[c];
    auto& candidates = kept[connectionKey(conn)];
    if (!candidates.empty() && remade.count(conn.from.node) == 0 &&
        remade.count(conn.to.node) == 0) {
      ConnectionItem* item = candidates.front();
      candidates.erase(candidates.begin());
      item->setIndex(c);
      now.push_back(item);
      continue;
    }
    PortItem* from = portItem(conn.from.node, conn.from.port);
    PortItem* to = portItem(conn.to.node, conn.to.port);
    if (from == nullptr || to == nullptr) continue;  // validation reports it
    std::string dataType = from->spec().data;
    if (dataType == app::kAnyData) dataType = to->spec().data;
    auto* item =
        new ConnectionItem(c, QPainterPath(), colorOfData(dataType), from->spec().stampsOnly);
    scene_->addItem(item);
    now.push_back(item);
  }
  for (auto& [key, items] : kept) {
    for (auto* item : items) delete item;
  }
  connections_ = std::move(now);
  routeConnections();

  if (!shown_ || changes.notesChanged || changes.framesChanged) syncNotesAndFrames();
  shown_ = app;
  decorate();
  // Room to scroll to everything, however far it lies.
  scene_->setSceneRect(scene_->itemsBoundingRect()
                           .adjusted(-2000, -2000, 2000, 2000)
                           .united(QRectF(-4000, -4000, 8000, 8000)));
}

void Canvas::routeConnections() {
  if (state_.app == nullptr) return;
  std::vector<QRectF> bodies;
  bodies.reserve(nodes_.size());
  for (const auto& [id, node] : nodes_) bodies.push_back(node->sceneBody());
  for (auto* item : connections_) {
    const auto& conn = state_.app->connections[item->index()];
    const PortItem* from = portItem(conn.from.node, conn.from.port);
    const PortItem* to = portItem(conn.to.node, conn.to.port);
    if (from == nullptr || to == nullptr) continue;
    item->setPath(routedCurve(from->scenePos(), to->scenePos(), bodies));
  }
}

}  // namespace vrflow::editor::gui
