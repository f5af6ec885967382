// Edits that place nodes: add a node already connected, insert a node on a connection, paste at
// a point.
#include <algorithm>
#include <limits>

#include "vrflow/app/loader.hpp"
#include "vrflow/app/package.hpp"
#include "vrflow/editor/structure_edit.hpp"

namespace vrflow::editor {

namespace {

bool isSyncPort(const app::PortSpec& port) {
  return port.name == app::kBeginItPort || port.name == app::kEndItPort;
}

// "module PACKAGE TYPE" or "filter TYPE" split in words.
std::vector<std::string> words(std::string_view spec) {
  std::vector<std::string> result;
  std::string word;
  for (const char c : spec) {
    if (c == ' ') {
      if (!word.empty()) result.push_back(word);
      word.clear();
    } else {
      word += c;
    }
  }
  if (!word.empty()) result.push_back(word);
  return result;
}

std::optional<std::pair<double, double>> topLeft(const std::vector<app::EditorNode>& nodes) {
  if (nodes.empty()) return std::nullopt;
  double x = std::numeric_limits<double>::max();
  double y = std::numeric_limits<double>::max();
  for (const auto& n : nodes) {
    x = std::min(x, n.x);
    y = std::min(y, n.y);
  }
  return std::make_pair(x, y);
}

}  // namespace

std::optional<std::string> firstCompatiblePort(const app::Application& app,
                                               const app::Catalog& catalog, std::string_view id,
                                               bool input, const app::Endpoint& other) {
  // beginIt/endIt take almost anything: they are offered only for a wire from one of them.
  const bool sync = other.port == app::kBeginItPort || other.port == app::kEndItPort;
  for (const auto& port : nodePorts(app, catalog, id)) {
    if (port.isInput != input || isSyncPort(port) != sync) continue;
    const app::Endpoint mine{std::string(id), port.name};
    const auto why = input ? connectionRefusal(app, catalog, other, mine)
                           : connectionRefusal(app, catalog, mine, other);
    if (!why) return port.name;
  }
  return std::nullopt;
}

std::vector<std::string> compatibleNodeSpecs(const app::Application& app,
                                             const app::Catalog& catalog,
                                             const app::Endpoint* other, bool otherIsOutput) {
  std::vector<std::string> specs;
  for (const auto* type : catalog.moduleTypes())
    specs.push_back("module " + type->package + " " + type->type);
  for (const auto* type : catalog.filterTypes()) specs.push_back("filter " + type->name);
  if (other == nullptr) return specs;
  std::erase_if(specs, [&](const std::string& spec) {
    return !addNodeFromSpec(app, catalog, spec, 0, 0, other, otherIsOutput);
  });
  return specs;
}

Result<Edit> addNodeFromSpec(const app::Application& app, const app::Catalog& catalog,
                             std::string_view spec, double x, double y, const app::Endpoint* other,
                             bool otherIsOutput, std::string* newId) {
  const auto parts = words(spec);
  std::string id;
  Result<Edit> added = makeError("'" + std::string(spec) + "' names no module or filter type");
  if (parts.size() == 3 && parts[0] == "module") {
    added = addModule(app, catalog, parts[1], parts[2], x, y, &id);
  } else if (parts.size() == 2 && parts[0] == "filter") {
    added = addFilter(app, catalog, parts[1], x, y, &id);
  }
  if (!added || other == nullptr) {
    if (added && newId != nullptr) *newId = id;
    return added;
  }
  const auto port = firstCompatiblePort(added->after, catalog, id, otherIsOutput, *other);
  if (!port) {
    return makeError("no " + std::string(otherIsOutput ? "input" : "output") + " of '" +
                     std::string(spec) + "' accepts '" + app::toString(*other) + "'");
  }
  const app::Endpoint mine{id, *port};
  auto connected = otherIsOutput ? connect(added->after, catalog, *other, mine)
                                 : connect(added->after, catalog, mine, *other);
  if (!connected) return connected;
  if (newId != nullptr) *newId = id;
  return Edit{added->label + " connected to " + app::toString(*other), app,
              std::move(connected->after)};
}

Result<Edit> insertOnConnection(const app::Application& app, const app::Catalog& catalog,
                                std::string_view id, std::size_t connection,
                                std::optional<std::pair<double, double>> position) {
  if (connection >= app.connections.size()) return makeError("no such connection");
  if (nodeKind(app, id) == NodeKind::None) return makeError("no node '" + std::string(id) + "'");
  const app::Connection old = app.connections[connection];
  if (old.from.node == id || old.to.node == id) {
    return makeError("'" + std::string(id) + "' is already an end of " + app::toString(old.from) +
                     " \u2192 " + app::toString(old.to));
  }
  app::Application after = app;
  after.connections.erase(after.connections.begin() + static_cast<std::ptrdiff_t>(connection));
  const auto in = firstCompatiblePort(after, catalog, id, true, old.from);
  if (!in) {
    return makeError("'" + std::string(id) + "' cannot be inserted: no input accepts what '" +
                     app::toString(old.from) + "' sends");
  }
  const auto out = firstCompatiblePort(after, catalog, id, false, old.to);
  if (!out) {
    return makeError("'" + std::string(id) + "' cannot be inserted: no output fits '" +
                     app::toString(old.to) + "'");
  }
  // The two halves take the old connection's place, with its queue settings.
  app::Connection first = old;
  first.to = {std::string(id), *in};
  first.loc = {};
  app::Connection second = old;
  second.from = {std::string(id), *out};
  second.loc = {};
  const auto at = after.connections.begin() + static_cast<std::ptrdiff_t>(connection);
  after.connections.insert(after.connections.insert(at, second), first);
  if (position) {
    auto moved = moveNodes(after, {{std::string(id), *position}});
    if (moved) after = std::move(moved->after);
  }
  return Edit{"Insert " + std::string(id) + " on " + app::toString(old.from) + " \u2192 " +
                  app::toString(old.to),
              app, std::move(after)};
}

Result<Edit> pasteXmlAt(const app::Application& app, std::string_view xml,
                        std::optional<std::pair<double, double>> corner,
                        std::vector<std::string>* pastedIds) {
  auto part = app::loadApplicationString(xml, "clipboard");
  const auto box = part ? topLeft(part->editor) : std::nullopt;
  double dx = 40, dy = 40;  // no positions to go by: the old offset
  if (box && corner) {
    dx = corner->first - box->first;
    dy = corner->second - box->second;
  } else if (box) {
    // Beside the copied nodes: one bounding box (plus a node's width for the last column) to
    // the right.
    double right = box->first;
    for (const auto& n : part->editor) right = std::max(right, n.x);
    dx = right - box->first + 200;
    dy = 0;
  }
  return pasteXml(app, xml, dx, dy, pastedIds);
}

}  // namespace vrflow::editor
