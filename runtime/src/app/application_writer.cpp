#include <string_view>

#include "composite_writer.hpp"
#include "file_io.hpp"
#include "text_util.hpp"
#include "vrflow/app/writer.hpp"
#include "xml_out.hpp"

namespace vrflow::app {
namespace {

using detail::closeSection;
using detail::closeTag;
using detail::openSection;
using detail::Tag;
using detail::writeComments;
using detail::writeParams;

// The <hosts> section is left out when it holds only what the loader adds to a file without
// one, so that such a file saves back unchanged.
bool onlyImplicitHost(const Application& app) {
  return app.hosts.empty() || (app.hosts.size() == 1 && app.hosts[0].id == kDefaultHostId &&
                               app.hosts[0].address == kDefaultHostAddress);
}

void writeHosts(std::string& out, const Application& app) {
  if (onlyImplicitHost(app)) return;
  openSection(out, app, "hosts");
  for (const Host& host : app.hosts) {
    writeComments(out, 2, host.comments);
    Tag(out, 2, "host")
        .attribute("id", host.id)
        .attributeUnless("address", host.address, kDefaultHostAddress)
        .close();
  }
  closeSection(out, app, "hosts");
}

void writePackageFolders(std::string& out, const Application& app) {
  for (const PackageFolder& folder : app.packages) {
    writeComments(out, 1, folder.comments);
    Tag(out, 1, "packages").attribute("path", folder.path).close();
  }
}

std::string defaultHost(const Application& app) {
  return app.hosts.empty() ? std::string() : app.hosts.front().id;
}

void writeModules(std::string& out, const Application& app) {
  if (app.modules.empty()) return;
  const std::string firstHost = defaultHost(app);
  openSection(out, app, "modules");
  for (const Module& module : app.modules) {
    writeComments(out, 2, module.comments);
    Tag tag(out, 2, "module");
    tag.attribute("id", module.id).attribute("package", module.package);
    tag.attribute("type", module.type);
    if (!module.host.empty()) tag.attributeUnless("host", module.host, firstHost);
    tag.attributeUnless("endit", toString(module.endIt), "after-iteration");
    if (module.params.empty() && module.inputs.empty() && module.endComments.empty()) {
      tag.close();
      continue;
    }
    tag.open();
    writeParams(out, 3, module.params);
    for (const InputConfig& input : module.inputs) {
      writeComments(out, 3, input.comments);
      Tag(out, 3, "input")
          .attribute("port", input.port)
          .attributeUnless("initial-messages", std::to_string(input.initialMessages), "0")
          .attributeUnless("mode", toString(input.mode), "fifo")
          .close();
    }
    writeComments(out, 3, module.endComments);
    closeTag(out, 2, "module");
  }
  closeSection(out, app, "modules");
}

void writeFilters(std::string& out, const Application& app) {
  if (app.filters.empty()) return;
  const std::string firstHost = defaultHost(app);
  openSection(out, app, "filters");
  for (const Filter& filter : app.filters) {
    writeComments(out, 2, filter.comments);
    Tag tag(out, 2, "filter");
    tag.attribute("id", filter.id).attribute("type", filter.type);
    if (!filter.host.empty()) tag.attributeUnless("host", filter.host, firstHost);
    if (!filter.plugin.empty()) tag.attribute("plugin", filter.plugin);
    if (filter.params.empty() && filter.endComments.empty()) {
      tag.close();
      continue;
    }
    tag.open();
    writeParams(out, 3, filter.params);
    writeComments(out, 3, filter.endComments);
    closeTag(out, 2, "filter");
  }
  closeSection(out, app, "filters");
}

// An endpoint the loader could not split keeps its text in `node`; it is written back as is.
std::string endpointText(const Endpoint& endpoint) {
  if (endpoint.port.empty()) return endpoint.node;
  return toString(endpoint);
}

void writeConnections(std::string& out, const Application& app) {
  if (app.connections.empty()) return;
  openSection(out, app, "connections");
  for (const Connection& connection : app.connections) {
    writeComments(out, 2, connection.comments);
    Tag(out, 2, "connection")
        .attribute("from", endpointText(connection.from))
        .attribute("to", endpointText(connection.to))
        .attributeUnless("capacity", std::to_string(connection.capacity), "0")
        .attributeUnless("policy", toString(connection.policy), "block")
        .close();
  }
  closeSection(out, app, "connections");
}

// Numbers are written as the reader reads them; `fallback` values are left out.
void numberUnless(Tag& tag, std::string_view name, double value, double fallback) {
  if (value != fallback) tag.attribute(name, detail::formatNumber(value));
}

void writeEditor(std::string& out, const Application& app) {
  if (app.editor.empty() && app.notes.empty() && app.frames.empty()) return;
  openSection(out, app, "editor");
  for (const EditorNode& node : app.editor) {
    writeComments(out, 2, node.comments);
    Tag tag(out, 2, "node");
    tag.attribute("ref", node.ref);
    numberUnless(tag, "x", node.x, 0);
    numberUnless(tag, "y", node.y, 0);
    tag.close();
  }
  const EditorNote noteDefaults;
  for (const EditorNote& note : app.notes) {
    writeComments(out, 2, note.comments);
    Tag tag(out, 2, "note");
    tag.attribute("id", note.id);
    numberUnless(tag, "x", note.x, 0);
    numberUnless(tag, "y", note.y, 0);
    numberUnless(tag, "width", note.width, noteDefaults.width);
    numberUnless(tag, "height", note.height, noteDefaults.height);
    tag.text(note.text);
    out += "</note>\n";
  }
  const EditorFrame frameDefaults;
  for (const EditorFrame& frame : app.frames) {
    writeComments(out, 2, frame.comments);
    Tag tag(out, 2, "frame");
    tag.attribute("id", frame.id);
    if (!frame.title.empty()) tag.attribute("title", frame.title);
    numberUnless(tag, "x", frame.x, 0);
    numberUnless(tag, "y", frame.y, 0);
    numberUnless(tag, "width", frame.width, frameDefaults.width);
    numberUnless(tag, "height", frame.height, frameDefaults.height);
    if (!frame.color.empty()) tag.attribute("color", frame.color);
    tag.close();
  }
  closeSection(out, app, "editor");
}

}  // namespace

std::string saveApplication(const Application& app) {
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  writeComments(out, 0, app.comments);
  Tag root(out, 0, "application");
  if (!app.name.empty()) root.attribute("name", app.name);
  root.attribute("version", "1");
  const bool empty = app.packages.empty() && onlyImplicitHost(app) && app.composites.empty() &&
                     app.modules.empty() && app.instances.empty() && app.filters.empty() &&
                     app.connections.empty() && app.editor.empty() && app.notes.empty() &&
                     app.frames.empty() && app.endComments.empty();
  if (empty) {
    root.close();
    writeComments(out, 0, app.afterComments);
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
  writeComments(out, 1, app.endComments);
  closeTag(out, 0, "application");
  writeComments(out, 0, app.afterComments);
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
