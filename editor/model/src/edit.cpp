#include "vrflow/editor/edit.hpp"

#include <algorithm>
#include <filesystem>
#include <set>
#include <sstream>

#include "vrflow/app/composite_file.hpp"
#include "vrflow/app/expand.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/writer.hpp"

namespace vrflow::editor {

namespace {

Result<Edit> makeEdit(std::string label, const app::Application& before, app::Application after) {
  return Edit{std::move(label), before, std::move(after)};
}

template <typename T>
bool eraseById(std::vector<T>& items, std::string_view id) {
  const auto it = std::find_if(items.begin(), items.end(), [&](const T& t) { return t.id == id; });
  if (it == items.end()) return false;
  items.erase(it);
  return true;
}

std::vector<app::Param>* paramsOf(app::Application& app, std::string_view id) {
  if (auto* m = app::findModule(app, id)) return &m->params;
  if (auto* f = app::findFilter(app, id)) return &f->params;
  for (auto& i : app.instances) {
    if (i.id == id) return &i.params;
  }
  return nullptr;
}

std::string* hostOf(app::Application& app, std::string_view id) {
  if (auto* m = app::findModule(app, id)) return &m->host;
  if (auto* f = app::findFilter(app, id)) return &f->host;
  for (auto& i : app.instances) {
    if (i.id == id) return &i.host;
  }
  return nullptr;
}

std::string firstHost(const app::Application& app) {
  return app.hosts.empty() ? std::string(app::kDefaultHostId) : app.hosts.front().id;
}

void ensureHost(app::Application& app) {
  if (app.hosts.empty()) {
    app.hosts.push_back(
        {std::string(app::kDefaultHostId), std::string(app::kDefaultHostAddress), {}});
  }
}

void setPosition(app::Application& app, const std::string& id, double x, double y) {
  for (auto& n : app.editor) {
    if (n.ref == id) {
      n.x = x;
      n.y = y;
      return;
    }
  }
  app.editor.emplace_back(id, x, y);
}

std::string sanitizeId(std::string_view text) {
  std::string id;
  for (const char c : text) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-';
    id += ok ? c : '_';
  }
  return id.empty() ? std::string("node") : id;
}

bool validId(std::string_view id) {
  if (id.empty()) return false;
  return std::all_of(id.begin(), id.end(), [](char c) {
    return c != '.' && c != ':' && c != ' ' && c != '"' && c != '<' && c != '>' && c != '&';
  });
}

std::optional<app::Composite> compositeFor(const app::Application& app, const app::Instance& inst) {
  if (const auto* c = app::findComposite(app, inst.composite)) return *c;
  const auto sources = app::defaultCompositeSources(app);
  for (const auto& dir : sources.searchPath) {
    const auto path =
        std::filesystem::path(dir) / (inst.composite + std::string(app::kCompositeFileSuffix));
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) continue;
    auto loaded = app::loadCompositeFile(path.string());
    if (loaded) return std::move(*loaded);
  }
  return std::nullopt;
}

/// Adds `node` (a module or a filter) to a copy of `app` with a new id from `type`, on the
/// first host, at (x, y) on the canvas: the edit labelled `label` and the id.
template <typename Node>
Result<Edit> addNode(const app::Application& app, std::vector<Node> app::Application::*nodes,
                     Node node, std::string_view type, double x, double y, std::string* newId,
                     const std::string& label) {
  app::Application after = app;
  ensureHost(after);
  node.id = uniqueId(app, type);
  node.type = type;
  node.host = firstHost(after);
  (after.*nodes).push_back(node);
  setPosition(after, node.id, x, y);
  if (newId != nullptr) *newId = node.id;
  return makeEdit(label + node.id, app, std::move(after));
}

}  // namespace

// ---- History ----------------------------------------------------------------------------

void History::push(Edit edit) {
  edits_.resize(index_);
  if (clean_ > index_) clean_ = static_cast<std::size_t>(-1);  // the clean state is gone
  edit.redo(app_);
  edits_.push_back(std::move(edit));
  ++index_;
}

bool History::undo() {
  if (!canUndo()) return false;
  edits_[--index_].undo(app_);
  return true;
}

bool History::redo() {
  if (!canRedo()) return false;
  edits_[index_++].redo(app_);
  return true;
}

// ---- Queries ----------------------------------------------------------------------------

NodeKind nodeKind(const app::Application& app, std::string_view id) {
  if (app::findModule(app, id) != nullptr) return NodeKind::Module;
  if (app::findFilter(app, id) != nullptr) return NodeKind::Filter;
  if (app::findInstance(app, id) != nullptr) return NodeKind::Instance;
  return NodeKind::None;
}

std::vector<std::string> nodeIds(const app::Application& app) {
  std::vector<std::string> ids;
  for (const auto& m : app.modules) ids.push_back(m.id);
  for (const auto& f : app.filters) ids.push_back(f.id);
  for (const auto& i : app.instances) ids.push_back(i.id);
  return ids;
}

std::vector<app::PortSpec> nodePorts(const app::Application& app, const app::Catalog& catalog,
                                     std::string_view id) {
  if (const auto* m = app::findModule(app, id)) return catalog.portsOf(*m);
  if (const auto* f = app::findFilter(app, id)) return catalog.portsOf(*f);
  if (const auto* i = app::findInstance(app, id)) {
    std::vector<app::PortSpec> ports;
    if (auto composite = compositeFor(app, *i)) {
      for (const auto& p : composite->inputs)
        ports.push_back({.name = p.name, .isInput = true, .data = "any", .doc = p.doc});
      for (const auto& p : composite->outputs)
        ports.push_back({.name = p.name, .isInput = false, .data = "any", .doc = p.doc});
    }
    return ports;
  }
  return {};
}

std::string uniqueId(const app::Application& app, std::string_view base) {
  const std::string stem = sanitizeId(base);
  if (nodeKind(app, stem) == NodeKind::None) return stem;
  for (int n = 2;; ++n) {
    std::string id = stem + std::to_string(n);
    if (nodeKind(app, id) == NodeKind::None) return id;
  }
}

std::optional<std::string> connectionRefusal(const app::Application& app,
                                             const app::Catalog& catalog, const app::Endpoint& from,
                                             const app::Endpoint& to) {
  const NodeKind fromKind = nodeKind(app, from.node);
  const NodeKind toKind = nodeKind(app, to.node);
  if (fromKind == NodeKind::None) return "no module or filter '" + from.node + "'";
  if (toKind == NodeKind::None) return "no module or filter '" + to.node + "'";
  const auto fromPorts = nodePorts(app, catalog, from.node);
  const auto toPorts = nodePorts(app, catalog, to.node);
  const app::PortSpec* out = app::findPort(fromPorts, from.port);
  const app::PortSpec* in = app::findPort(toPorts, to.port);
  if (out == nullptr) return "'" + from.node + "' has no port '" + from.port + "'";
  if (in == nullptr) return "'" + to.node + "' has no port '" + to.port + "'";
  if (out->isInput && !in->isInput)
    return "connect an output to an input, not an input to an output";
  if (out->isInput)
    return "'" + app::toString(from) + "' is an input: a connection starts at an output";
  if (!in->isInput)
    return "'" + app::toString(to) + "' is an output: a connection ends at an input";
  if (out->data != in->data && out->data != app::kAnyData && in->data != app::kAnyData) {
    return "port data types differ: '" + app::toString(from) + "' sends '" + out->data + "' but '" +
           app::toString(to) + "' expects '" + in->data + "'";
  }
  if (toKind == NodeKind::Module && !in->stampsOnly && fromKind == NodeKind::Module &&
      out->stampsOnly) {
    return "'" + app::toString(from) + "' sends stamps-only messages but '" + app::toString(to) +
           "' expects full messages";
  }
  for (const auto& c : app.connections) {
    if (c.from.node == from.node && c.from.port == from.port && c.to.node == to.node &&
        c.to.port == to.port) {
      return "'" + app::toString(from) + "' is already connected to '" + app::toString(to) + "'";
    }
  }
  return std::nullopt;
}

// ---- Node edits --------------------------------------------------------------------------

Result<Edit> addModule(const app::Application& app, const app::Catalog& catalog,
                       std::string_view package, std::string_view type, double x, double y,
                       std::string* newId) {
  if (catalog.findModule(package, type) == nullptr) {
    return makeError("no module type '" + std::string(package) + "/" + std::string(type) + "'");
  }
  app::Module module;
  module.package = package;
  return addNode(app, &app::Application::modules, std::move(module), type, x, y, newId,
                 "Add module ");
}

Result<Edit> addFilter(const app::Application& app, const app::Catalog& catalog,
                       std::string_view type, double x, double y, std::string* newId) {
  if (catalog.findFilter(type) == nullptr)
    return makeError("no filter type '" + std::string(type) + "'");
  return addNode(app, &app::Application::filters, app::Filter{}, type, x, y, newId, "Add filter ");
}

Result<Edit> removeNodes(const app::Application& app, const std::vector<std::string>& ids) {
  app::Application after = app;
  const std::set<std::string> gone(ids.begin(), ids.end());
  std::size_t removed = 0;
  for (const auto& id : gone) {
    if (eraseById(after.modules, id) || eraseById(after.filters, id) ||
        eraseById(after.instances, id)) {
      ++removed;
    }
  }
  if (removed == 0) return makeError("nothing to delete");
  std::erase_if(after.connections, [&](const app::Connection& c) {
    return gone.count(c.from.node) != 0 || gone.count(c.to.node) != 0;
  });
  std::erase_if(after.editor, [&](const app::EditorNode& n) { return gone.count(n.ref) != 0; });
  return makeEdit(
      removed == 1 ? "Delete " + *gone.begin() : "Delete " + std::to_string(removed) + " nodes",
      app, std::move(after));
}

Result<Edit> connect(const app::Application& app, const app::Catalog& catalog,
                     const app::Endpoint& from, const app::Endpoint& to) {
  if (auto why = connectionRefusal(app, catalog, from, to)) return makeError(*why);
  app::Application after = app;
  app::Connection c;
  c.from = from;
  c.to = to;
  after.connections.push_back(c);
  return makeEdit("Connect " + app::toString(from) + " to " + app::toString(to), app,
                  std::move(after));
}

Result<Edit> disconnect(const app::Application& app, std::vector<std::size_t> indexes) {
  std::sort(indexes.begin(), indexes.end());
  indexes.erase(std::unique(indexes.begin(), indexes.end()), indexes.end());
  if (indexes.empty() || indexes.back() >= app.connections.size())
    return makeError("no such connection");
  app::Application after = app;
  for (auto it = indexes.rbegin(); it != indexes.rend(); ++it) {
    after.connections.erase(after.connections.begin() + static_cast<std::ptrdiff_t>(*it));
  }
  return makeEdit(indexes.size() == 1 ? "Delete connection" : "Delete connections", app,
                  std::move(after));
}

Result<Edit> setParameter(const app::Application& app, std::string_view node, std::string_view name,
                          std::string value) {
  app::Application after = app;
  auto* params = paramsOf(after, node);
  if (params == nullptr) return makeError("no node '" + std::string(node) + "'");
  if (value.empty()) {
    const auto before = params->size();
    std::erase_if(*params, [&](const app::Param& p) { return p.name == name; });
    if (params->size() == before)
      return makeError("parameter '" + std::string(name) + "' is not set");
  } else {
    const auto* current = app::findParam(*params, name);
    if (current != nullptr && current->value == value) return makeError("unchanged");
    app::setParam(*params, name, std::move(value));
  }
  return makeEdit("Set " + std::string(node) + "." + std::string(name), app, std::move(after));
}

Result<Edit> renameParameter(const app::Application& app, std::string_view node,
                             std::string_view name, std::string_view newName) {
  app::Application after = app;
  auto* params = paramsOf(after, node);
  if (params == nullptr) return makeError("no node '" + std::string(node) + "'");
  if (app::findParam(*params, newName) != nullptr) {
    return makeError("parameter '" + std::string(newName) + "' is already set on " +
                     std::string(node));
  }
  const auto it = std::find_if(params->begin(), params->end(),
                               [&](const app::Param& p) { return p.name == name; });
  if (it == params->end()) return makeError("parameter '" + std::string(name) + "' is not set");
  it->name = newName;
  return makeEdit(
      "Rename " + std::string(node) + "." + std::string(name) + " to " + std::string(newName), app,
      std::move(after));
}

Result<Edit> setInitialMessages(const app::Application& app, std::string_view module,
                                std::string_view port, int count) {
  if (count < 0) return makeError("initial messages must not be negative");
  app::Application after = app;
  auto* m = app::findModule(after, module);
  if (m == nullptr) return makeError("no module '" + std::string(module) + "'");
  auto it = std::find_if(m->inputs.begin(), m->inputs.end(),
                         [&](const app::InputConfig& i) { return i.port == port; });
  if (it == m->inputs.end()) {
    if (count == 0) return makeError("unchanged");
    app::InputConfig input;
    input.port = port;
    input.initialMessages = count;
    m->inputs.push_back(input);
  } else {
    if (it->initialMessages == count) return makeError("unchanged");
    it->initialMessages = count;
    if (count == 0 && it->mode == app::InputMode::Fifo) m->inputs.erase(it);
  }
  return makeEdit("Initial messages of " + std::string(module) + "." + std::string(port), app,
                  std::move(after));
}

Result<Edit> moveNodes(const app::Application& app,
                       const std::map<std::string, std::pair<double, double>>& positions) {
  app::Application after = app;
  bool changed = false;
  for (const auto& [id, xy] : positions) {
    if (nodeKind(app, id) == NodeKind::None) continue;
    const auto* old = app::findEditorNode(app, id);
    if (old != nullptr && old->x == xy.first && old->y == xy.second) continue;
    setPosition(after, id, xy.first, xy.second);
    changed = true;
  }
  if (!changed) return makeError("unchanged");
  return makeEdit(positions.size() == 1 ? "Move " + positions.begin()->first : "Move nodes", app,
                  std::move(after));
}

Result<Edit> renameNode(const app::Application& app, std::string_view id, std::string newId) {
  if (nodeKind(app, id) == NodeKind::None) return makeError("no node '" + std::string(id) + "'");
  if (!validId(newId))
    return makeError("'" + newId + "' is not a valid id (no '.', ':' or spaces)");
  if (newId == id) return makeError("unchanged");
  if (nodeKind(app, newId) != NodeKind::None) return makeError("'" + newId + "' is already used");
  app::Application after = app;
  if (auto* m = app::findModule(after, id)) m->id = newId;
  if (auto* f = app::findFilter(after, id)) f->id = newId;
  for (auto& i : after.instances) {
    if (i.id == id) i.id = newId;
  }
  for (auto& c : after.connections) {
    if (c.from.node == id) c.from.node = newId;
    if (c.to.node == id) c.to.node = newId;
  }
  for (auto& n : after.editor) {
    if (n.ref == id) n.ref = newId;
  }
  return makeEdit("Rename " + std::string(id) + " to " + newId, app, std::move(after));
}

// ---- Hosts -------------------------------------------------------------------------------

Result<Edit> assignHost(const app::Application& app, const std::vector<std::string>& nodes,
                        std::string_view host) {
  if (app::findHost(app, host) == nullptr) return makeError("no host '" + std::string(host) + "'");
  app::Application after = app;
  bool changed = false;
  for (const auto& id : nodes) {
    std::string* h = hostOf(after, id);
    if (h == nullptr) return makeError("no node '" + id + "'");
    if (*h != host) {
      *h = host;
      changed = true;
    }
  }
  if (!changed) return makeError("unchanged");
  return makeEdit("Assign to host " + std::string(host), app, std::move(after));
}

Result<Edit> addHost(const app::Application& app, std::string id, std::string address) {
  if (!validId(id)) return makeError("'" + id + "' is not a valid host id");
  if (app::findHost(app, id) != nullptr) return makeError("host '" + id + "' exists already");
  app::Application after = app;
  ensureHost(after);
  after.hosts.push_back(
      {id, address.empty() ? std::string(app::kDefaultHostAddress) : address, {}});
  return makeEdit("Add host " + id, app, std::move(after));
}

namespace {

// Puts every module, filter and composite instance placed on host `from` on host `to`.
void moveNodesToHost(app::Application& app, std::string_view from, const std::string& to) {
  auto move = [&](auto& nodes) {
    for (auto& node : nodes) {
      if (node.host == from) node.host = to;
    }
  };
  move(app.modules);
  move(app.filters);
  move(app.instances);
}

}  // namespace

Result<Edit> removeHost(const app::Application& app, std::string_view id) {
  if (app::findHost(app, id) == nullptr) return makeError("no host '" + std::string(id) + "'");
  if (app.hosts.size() == 1) return makeError("the last host cannot be removed");
  app::Application after = app;
  eraseById(after.hosts, id);
  moveNodesToHost(after, id, after.hosts.front().id);
  return makeEdit("Remove host " + std::string(id), app, std::move(after));
}

Result<Edit> renameHost(const app::Application& app, std::string_view id, std::string newId) {
  if (app::findHost(app, id) == nullptr) return makeError("no host '" + std::string(id) + "'");
  if (!validId(newId)) return makeError("'" + newId + "' is not a valid host id");
  if (newId == id) return makeError("unchanged");
  if (app::findHost(app, newId) != nullptr) return makeError("host '" + newId + "' exists already");
  app::Application after = app;
  for (auto& h : after.hosts) {
    if (h.id == id) h.id = newId;
  }
  moveNodesToHost(after, id, newId);
  return makeEdit("Rename host " + std::string(id) + " to " + newId, app, std::move(after));
}

Result<Edit> setHostAddress(const app::Application& app, std::string_view id, std::string address) {
  app::Application after = app;
  for (auto& h : after.hosts) {
    if (h.id != id) continue;
    if (h.address == address) return makeError("unchanged");
    if (address.empty()) return makeError("a host needs an address");
    h.address = std::move(address);
    return makeEdit("Address of host " + std::string(id), app, std::move(after));
  }
  return makeError("no host '" + std::string(id) + "'");
}

Result<Edit> importHostfile(const app::Application& app, std::string_view text) {
  app::Application after = app;
  ensureHost(after);
  std::istringstream lines{std::string(text)};
  std::string line;
  int lineNumber = 0;
  int count = 0;
  while (std::getline(lines, line)) {
    ++lineNumber;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::string name;
    if (!(words >> name)) continue;
    std::string address = name;
    std::string word;
    while (words >> word) {
      if (word.find('=') == std::string::npos) address = word;  // slots=N and the like are ignored
    }
    if (!validId(name)) {
      // A host named by its address ("10.0.0.2") becomes id "10-0-0-2".
      std::replace(name.begin(), name.end(), '.', '-');
      std::replace(name.begin(), name.end(), ':', '-');
      if (!validId(name))
        return makeError("hostfile line " + std::to_string(lineNumber) + ": bad host name");
    }
    bool found = false;
    for (auto& h : after.hosts) {
      if (h.id == name) {
        h.address = address;
        found = true;
      }
    }
    if (!found) after.hosts.push_back({name, address, {}});
    ++count;
  }
  if (count == 0) return makeError("the hostfile names no host");
  return makeEdit("Import " + std::to_string(count) + " hosts", app, std::move(after));
}

// ---- Clipboard ---------------------------------------------------------------------------

std::string copyAsXml(const app::Application& app, const std::vector<std::string>& ids) {
  const std::set<std::string> chosen(ids.begin(), ids.end());
  app::Application part;
  part.name = "clipboard";
  part.hosts = app.hosts;
  for (const auto& m : app.modules) {
    if (chosen.count(m.id) != 0) part.modules.push_back(m);
  }
  for (const auto& f : app.filters) {
    if (chosen.count(f.id) != 0) part.filters.push_back(f);
  }
  for (const auto& i : app.instances) {
    if (chosen.count(i.id) != 0) part.instances.push_back(i);
  }
  for (const auto& c : app.connections) {
    if (chosen.count(c.from.node) != 0 && chosen.count(c.to.node) != 0)
      part.connections.push_back(c);
  }
  for (const auto& n : app.editor) {
    if (chosen.count(n.ref) != 0) part.editor.push_back(n);
  }
  return app::saveApplication(part);
}

Result<Edit> pasteXml(const app::Application& app, std::string_view xml, double dx, double dy,
                      std::vector<std::string>* pastedIds) {
  auto part = app::loadApplicationString(xml, "clipboard");
  if (!part) return makeError("the clipboard holds no vrflow nodes: " + part.error().message);
  if (part->modules.empty() && part->filters.empty() && part->instances.empty()) {
    return makeError("the clipboard holds no vrflow nodes");
  }
  app::Application after = app;
  ensureHost(after);
  std::map<std::string, std::string> renamed;
  auto fresh = [&](const std::string& id) {
    std::string newId = uniqueId(after, id);
    // Also avoid ids of nodes pasted just before (they are in `after` already).
    renamed[id] = newId;
    return newId;
  };
  auto hostHere = [&](const std::string& host) {
    return app::findHost(after, host) != nullptr ? host : after.hosts.front().id;
  };
  std::vector<std::string> ids;
  auto paste = [&](auto nodes, auto& into) {
    for (auto& node : nodes) {
      node.id = fresh(node.id);
      node.host = hostHere(node.host);
      ids.push_back(node.id);
      into.push_back(std::move(node));
    }
  };
  paste(part->modules, after.modules);
  paste(part->filters, after.filters);
  paste(part->instances, after.instances);
  for (auto c : part->connections) {
    if (renamed.count(c.from.node) == 0 || renamed.count(c.to.node) == 0) continue;
    c.from.node = renamed[c.from.node];
    c.to.node = renamed[c.to.node];
    after.connections.push_back(std::move(c));
  }
  for (const auto& n : part->editor) {
    if (renamed.count(n.ref) == 0) continue;
    after.editor.emplace_back(renamed[n.ref], n.x + dx, n.y + dy);
  }
  if (pastedIds != nullptr) *pastedIds = ids;
  return makeEdit(
      ids.size() == 1 ? "Paste " + ids.front() : "Paste " + std::to_string(ids.size()) + " nodes",
      app, std::move(after));
}

std::string textToSave(const app::Application& app, const OpenedText& opened) {
  std::string canonical = app::saveApplication(app);
  if (!opened.text.empty() && canonical == opened.canonical) return opened.text;
  return canonical;
}

}  // namespace vrflow::editor
