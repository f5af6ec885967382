#include <string_view>

#include "composite_writer.hpp"
#include "file_io.hpp"
#include "text_util.hpp"
#include "vrflow/app/writer.hpp"
#include "xml_out.hpp"

namespace vrflow::app {
namespace {

using detail::closeTag;
using detail::Tag;

void writeParams(std::string& out, int depth, const std::vector<Param>& params) {
  for (const Param& param : params) {
    Tag(out, depth, "param").attribute("name", param.name).attribute("value", param.value).close();
  }
}

// The <hosts> section is left out when it holds only what the loader adds to a file without
// one, so that such a file saves back unchanged.
bool onlyImplicitHost(const Application& app) {
  return app.hosts.empty() || (app.hosts.size() == 1 && app.hosts[0].id == kDefaultHostId &&
                               app.hosts[0].address == kDefaultHostAddress);
}

void writeHosts(std::string& out, const Application& app) {
  if (onlyImplicitHost(app)) return;
  Tag(out, 1, "hosts").open();
  for (const Host& host : app.hosts) {
    Tag(out, 2, "host")
        .attribute("id", host.id)
        .attributeUnless("address", host.address, kDefaultHostAddress)
        .close();
  }
  closeTag(out, 1, "hosts");
}

void writePackageFolders(std::string& out, const Application& app) {
  for (const PackageFolder& folder : app.packages) {
    Tag(out, 1, "packages").attribute("path", folder.path).close();
  }
}

std::string defaultHost(const Application& app) {
  return app.hosts.empty() ? std::string() : app.hosts.front().id;
}

void writeModules(std::string& out, const Application& app) {
  if (app.modules.empty()) return;
  const std::string firstHost = defaultHost(app);
  Tag(out, 1, "modules").open();
  for (const Module& module : app.modules) {
    Tag tag(out, 2, "module");
    tag.attribute("id", module.id).attribute("package", module.package);
    tag.attribute("type", module.type);
    if (!module.host.empty()) tag.attributeUnless("host", module.host, firstHost);
    tag.attributeUnless("endit", toString(module.endIt), "after-iteration");
    if (module.params.empty() && module.inputs.empty()) {
      tag.close();
      continue;
    }
    tag.open();
    writeParams(out, 3, module.params);
    for (const InputConfig& input : module.inputs) {
      Tag(out, 3, "input")
          .attribute("port", input.port)
          .attributeUnless("initial-messages", std::to_string(input.initialMessages), "0")
          .attributeUnless("mode", toString(input.mode), "fifo")
          .close();
    }
    closeTag(out, 2, "module");
  }
  closeTag(out, 1, "modules");
}

void writeFilters(std::string& out, const Application& app) {
  if (app.filters.empty()) return;
  const std::string firstHost = defaultHost(app);
  Tag(out, 1, "filters").open();
  for (const Filter& filter : app.filters) {
    Tag tag(out, 2, "filter");
    tag.attribute("id", filter.id).attribute("type", filter.type);
    if (!filter.host.empty()) tag.attributeUnless("host", filter.host, firstHost);
    if (!filter.plugin.empty()) tag.attribute("plugin", filter.plugin);
    if (filter.params.empty()) {
      tag.close();
      continue;
    }
    tag.open();
    writeParams(out, 3, filter.params);
    closeTag(out, 2, "filter");
  }
  closeTag(out, 1, "filters");
}

// An endpoint the loader could not split keeps its text in `node`; it is written back as is.
std::string endpointText(const Endpoint& endpoint) {
  if (endpoint.port.empty()) return endpoint.node;
  return toString(endpoint);
}

void writeConnections(std::string& out, const Application& app) {
  if (app.connections.empty()) return;
  Tag(out, 1, "connections").open();
  for (const Connection& connection : app.connections) {
    Tag(out, 2, "connection")
        .attribute("from", endpointText(connection.from))
        .attribute("to", endpointText(connection.to))
        .attributeUnless("capacity", std::to_string(connection.capacity), "0")
        .attributeUnless("policy", toString(connection.policy), "block")
        .close();
  }
  closeTag(out, 1, "connections");
}

void writeEditor(std::string& out, const Application& app) {
  if (app.editor.empty()) return;
  Tag(out, 1, "editor").open();
  for (const EditorNode& node : app.editor) {
    Tag tag(out, 2, "node");
    tag.attribute("ref", node.ref);
    if (node.x != 0) tag.attribute("x", detail::formatNumber(node.x));
    if (node.y != 0) tag.attribute("y", detail::formatNumber(node.y));
    tag.close();
  }
  closeTag(out, 1, "editor");
}

}  // namespace

std::string saveApplication(const Application& app) {
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  Tag root(out, 0, "application");
  if (!app.name.empty()) root.attribute("name", app.name);
  root.attribute("version", "1");
  const bool empty = app.packages.empty() && onlyImplicitHost(app) && app.composites.empty() &&
                     app.modules.empty() && app.instances.empty() && app.filters.empty() &&
                     app.connections.empty() && app.editor.empty();
  if (empty) {
    root.close();
    return out;
  }
  root.open();
  writePackageFolders(out, app);
  writeHosts(out, app);
  detail::writeComposites(out, app);
  writeModules(out, app);
  detail::writeInstances(out, app);
  writeFilters(out, app);
  writeConnections(out, app);
  writeEditor(out, app);
  closeTag(out, 0, "application");
  return out;
}

Status saveApplicationFile(const Application& app, const std::string& path) {
  try {
    return detail::writeWholeFile(path, saveApplication(app));
  } catch (const std::exception& e) {
    return makeError(path + ": error: cannot save application (" + e.what() + ")");
  }
}

}  // namespace vrflow::app
