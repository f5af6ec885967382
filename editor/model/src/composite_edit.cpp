// Composites on the canvas: a selection collapsed into a new composite, and the inside of an
// instance.
#include <algorithm>
#include <limits>
#include <map>
#include <set>

#include "vrflow/app/expand.hpp"
#include "vrflow/editor/structure_edit.hpp"

namespace vrflow::editor {

namespace {

using Attributes = std::vector<app::TemplateAttribute>;

// A template element as the composite reader would make it from the same XML (attributes in
// canonical order, absent ones left out).
app::TemplateElement element(std::string name, Attributes attributes,
                             std::vector<app::TemplateElement> children = {}) {
  std::erase_if(attributes, [](const app::TemplateAttribute& a) { return a.value.empty(); });
  return {std::move(name), std::move(attributes), std::move(children), {}};
}

std::vector<app::TemplateElement> paramElements(const std::vector<app::Param>& params) {
  std::vector<app::TemplateElement> result;
  for (const auto& p : params)
    result.push_back({"param", {{"name", p.name}, {"value", p.value}}, {}, {}});
  return result;
}

// Why a node's text cannot go into a composite body as it is, or nullopt.
std::optional<std::string> templateProblem(std::string_view id,
                                           const std::vector<app::Param>& params) {
  for (const auto& p : params) {
    if (p.value.find("${") != std::string::npos) {
      return "parameter '" + p.name + "' of '" + std::string(id) +
             "' holds '${', which a composite would substitute";
    }
  }
  return std::nullopt;
}

app::TemplateElement moduleElement(const app::Module& m) {
  auto children = paramElements(m.params);
  for (const auto& in : m.inputs) {
    const std::string initial = in.initialMessages != 0 ? std::to_string(in.initialMessages) : "";
    const std::string mode = in.mode != app::InputMode::Fifo ? app::toString(in.mode) : "";
    children.push_back(
        element("input", {{"port", in.port}, {"initial-messages", initial}, {"mode", mode}}));
  }
  const std::string endit =
      m.endIt != app::EndItTiming::AfterIteration ? app::toString(m.endIt) : "";
  return element(
      "module",
      {{"id", m.id}, {"package", m.package}, {"type", m.type}, {"host", m.host}, {"endit", endit}},
      std::move(children));
}

app::TemplateElement connectionElement(const app::Connection& c) {
  const std::string capacity = c.capacity != 0 ? std::to_string(c.capacity) : "";
  const std::string policy = c.policy != app::QueuePolicy::Block ? app::toString(c.policy) : "";
  return element("connection", {{"from", app::toString(c.from)},
                                {"to", app::toString(c.to)},
                                {"capacity", capacity},
                                {"policy", policy}});
}

bool compositeNameTaken(const app::Application& app, const std::string& name) {
  if (app::findComposite(app, name) != nullptr) return true;
  return std::any_of(app.instances.begin(), app.instances.end(),
                     [&](const app::Instance& i) { return i.composite == name; });
}

}  // namespace

Result<Edit> collapseToComposite(const app::Application& app, const std::vector<std::string>& ids,
                                 std::string_view name, std::string* instanceId) {
  if (ids.empty()) return makeError("select the nodes to collapse first");
  const std::set<std::string> chosen(ids.begin(), ids.end());
  app::Composite composite;
  composite.name = std::string(name.empty() ? "group" : name);
  for (int n = 2; compositeNameTaken(app, composite.name); ++n)
    composite.name = std::string(name) + std::to_string(n);
  composite.doc = "collapsed from " + std::to_string(chosen.size()) + " nodes in the editor";

  app::Application after = app;
  std::string host;
  for (const auto& id : ids) {
    if (nodeKind(app, id) == NodeKind::None) return makeError("no node '" + id + "'");
  }
  for (const auto& m : app.modules) {
    if (chosen.count(m.id) == 0) continue;
    if (auto why = templateProblem(m.id, m.params)) return makeError(*why);
    composite.modules.push_back(moduleElement(m));
    if (host.empty()) host = m.host;
  }
  for (const auto& f : app.filters) {
    if (chosen.count(f.id) == 0) continue;
    if (!f.plugin.empty()) {
      return makeError("filter '" + f.id + "' comes from plugin " + f.plugin +
                       ": a composite cannot load a plugin; leave it out of the selection");
    }
    if (auto why = templateProblem(f.id, f.params)) return makeError(*why);
    composite.filters.push_back(element(
        "filter", {{"id", f.id}, {"type", f.type}, {"host", f.host}}, paramElements(f.params)));
    if (host.empty()) host = f.host;
  }
  for (const auto& i : app.instances) {
    if (chosen.count(i.id) == 0) continue;
    if (auto why = templateProblem(i.id, i.params)) return makeError(*why);
    composite.instances.push_back(
        element("instance", {{"id", i.id}, {"composite", i.composite}, {"host", i.host}},
                paramElements(i.params)));
    if (host.empty()) host = i.host;
  }
  std::erase_if(after.modules, [&](const app::Module& m) { return chosen.count(m.id) != 0; });
  std::erase_if(after.filters, [&](const app::Filter& f) { return chosen.count(f.id) != 0; });
  std::erase_if(after.instances, [&](const app::Instance& i) { return chosen.count(i.id) != 0; });

  app::Instance instance;
  instance.id = uniqueId(after, composite.name);
  instance.composite = composite.name;
  instance.host = app::effectiveHost(app, host);

  // Each inner endpoint that a connection across the border uses becomes one exposed port.
  std::set<std::string> portNames;
  std::map<std::string, std::string> exposed;  // inner "node.port" -> exposed port name
  auto expose = [&](const app::Endpoint& inner, bool input) {
    const std::string endpoint = app::toString(inner);
    if (auto it = exposed.find(endpoint); it != exposed.end()) return it->second;
    std::string portName = inner.port;
    if (portNames.count(portName) != 0) portName = inner.node + "_" + inner.port;
    for (int n = 2; portNames.count(portName) != 0; ++n)
      portName = inner.node + "_" + inner.port + std::to_string(n);
    portNames.insert(portName);
    exposed[endpoint] = portName;
    (input ? composite.inputs : composite.outputs).push_back({portName, endpoint, "", {}});
    return portName;
  };
  std::vector<app::Connection> outer;
  for (const auto& c : app.connections) {
    const bool fromInside = chosen.count(c.from.node) != 0;
    const bool toInside = chosen.count(c.to.node) != 0;
    if (fromInside && toInside) {
      composite.connections.push_back(connectionElement(c));
      continue;
    }
    app::Connection kept = c;
    if (fromInside) kept.from = {instance.id, expose(c.from, false)};
    if (toInside) kept.to = {instance.id, expose(c.to, true)};
    outer.push_back(std::move(kept));
  }
  after.connections = std::move(outer);

  // The instance stands where the nodes' bounding box began.
  std::optional<std::pair<double, double>> corner;
  for (const auto& n : app.editor) {
    if (chosen.count(n.ref) == 0) continue;
    corner = corner ? std::make_pair(std::min(corner->first, n.x), std::min(corner->second, n.y))
                    : std::make_pair(n.x, n.y);
  }
  std::erase_if(after.editor, [&](const app::EditorNode& n) { return chosen.count(n.ref) != 0; });
  if (corner) after.editor.emplace_back(instance.id, corner->first, corner->second);

  after.composites.push_back(std::move(composite));
  after.instances.push_back(instance);
  if (instanceId != nullptr) *instanceId = instance.id;
  return Edit{
      "Collapse " + std::to_string(chosen.size()) + " nodes into composite " + instance.composite,
      app, std::move(after)};
}

Result<app::Application> compositeInside(const app::Application& app, std::string_view instance) {
  const app::Instance* found = app::findInstance(app, instance);
  if (found == nullptr) return makeError("no composite instance '" + std::string(instance) + "'");
  app::Application one;
  one.name = app.name;
  one.hosts = app.hosts;
  one.composites = app.composites;
  one.file = app.file;
  one.instances.push_back(*found);
  auto flat = app::expandComposites(one, app::defaultCompositeSources(app));
  if (!flat) return makeError(flat.error().message);
  const std::string prefix = found->id + app::kInstanceSeparator;
  auto strip = [&](std::string& id) {
    if (id.rfind(prefix, 0) == 0) id.erase(0, prefix.size());
  };
  for (auto& m : flat->modules) strip(m.id);
  for (auto& f : flat->filters) strip(f.id);
  for (auto& c : flat->connections) {
    strip(c.from.node);
    strip(c.to.node);
  }
  flat->editor.clear();
  return flat;
}

}  // namespace vrflow::editor
