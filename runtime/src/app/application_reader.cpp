#include "application_reader.hpp"

#include <algorithm>
#include <array>

#include "composite_reader.hpp"
#include "element_reader.hpp"
#include "file_io.hpp"
#include "source_text.hpp"
#include "text_util.hpp"
#include "vrflow/app/loader.hpp"

namespace vrflow::app {
namespace {

using detail::ElementReader;
using detail::ReadContext;

// `packages` may be written several times, before every other section.
constexpr std::array<std::string_view, 8> kSections = {
    "packages", "hosts", "composites", "modules", "instances", "filters", "connections", "editor"};

// Reports text or elements inside an element that holds neither.
void expectEmpty(const ReadContext& context, const pugi::xml_node& node) {
  detail::forEachChild(context, node, {}, [](const pugi::xml_node&) {});
}

}  // namespace

Param detail::readParam(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node, {"name", "value"});
  Param param;
  param.name = reader.required("name");
  if (!reader.has("value")) {
    context.error(reader.loc(), detail::missingAttributeMessage("param", "value"));
  }
  param.value = reader.text("value");
  param.loc = reader.loc();
  param.comments = detail::commentsBefore(node);
  expectEmpty(context, node);
  return param;
}

namespace {

Host readHost(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node, {"id", "address"});
  Host host;
  host.id = reader.required("id");
  host.address = reader.text("address", kDefaultHostAddress);
  host.loc = reader.loc();
  host.comments = detail::commentsBefore(node);
  expectEmpty(context, node);
  return host;
}

InputConfig readInput(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node, {"port", "initial-messages", "mode"});
  InputConfig input;
  input.port = reader.required("port");
  input.initialMessages = reader.integer("initial-messages", 0);
  input.mode = reader.keyword("mode", InputMode::Fifo, parseInputMode, "fifo, latest");
  input.loc = reader.loc();
  input.comments = detail::commentsBefore(node);
  expectEmpty(context, node);
  return input;
}

Module readModule(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node, {"id", "package", "type", "host", "endit"});
  Module module;
  module.id = reader.required("id");
  module.package = reader.required("package");
  module.type = reader.required("type");
  module.host = reader.text("host");
  module.endIt = reader.keyword("endit", EndItTiming::AfterIteration, parseEndItTiming,
                                "after-iteration, after-wait");
  module.loc = reader.loc();
  module.comments = detail::commentsBefore(node);
  module.endComments = detail::trailingComments(node);
  detail::forEachChild(context, node, {"param", "input"}, [&](const pugi::xml_node& child) {
    if (std::string_view(child.name()) == "param") {
      module.params.push_back(readParam(context, child));
    } else {
      module.inputs.push_back(readInput(context, child));
    }
  });
  return module;
}

Filter readFilter(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node, {"id", "type", "host", "plugin"});
  Filter filter;
  filter.id = reader.required("id");
  filter.type = reader.required("type");
  filter.host = reader.text("host");
  filter.plugin = reader.text("plugin");
  filter.loc = reader.loc();
  filter.comments = detail::commentsBefore(node);
  filter.endComments = detail::trailingComments(node);
  detail::forEachChild(context, node, {"param"}, [&](const pugi::xml_node& child) {
    filter.params.push_back(readParam(context, child));
  });
  return filter;
}

// A malformed endpoint keeps its whole text as the node and an empty port, which validate()
// reports with the same message as here.
Endpoint readEndpoint(const ElementReader& reader, const char* attribute) {
  const std::string text = reader.required(attribute);
  if (text.empty()) return {};
  if (std::optional<Endpoint> endpoint = parseEndpoint(text)) return *endpoint;
  reader.errorAt(attribute, "endpoint '" + text + "' must be written node.port");
  return Endpoint{text, ""};
}

Connection readConnection(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node, {"from", "to", "capacity", "policy"});
  Connection connection;
  connection.from = readEndpoint(reader, "from");
  connection.to = readEndpoint(reader, "to");
  connection.capacity = reader.integer("capacity", 0);
  connection.policy = reader.keyword("policy", QueuePolicy::Block, parseQueuePolicy,
                                     "block, drop-oldest, drop-newest");
  connection.loc = reader.loc();
  connection.comments = detail::commentsBefore(node);
  expectEmpty(context, node);
  return connection;
}

PackageFolder readPackageFolder(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node, {"path"});
  PackageFolder folder;
  folder.path = reader.required("path");
  folder.loc = reader.loc();
  folder.comments = detail::commentsBefore(node);
  expectEmpty(context, node);
  return folder;
}

void readSection(const ReadContext& context, const pugi::xml_node& section, Application& app) {
  const std::string_view name = section.name();
  if (name == "packages") {
    app.packages.push_back(readPackageFolder(context, section));
    return;
  }
  const ElementReader reader(context, section, {});
  SectionComments comments{std::string(name), detail::commentsBefore(section),
                           detail::trailingComments(section)};
  if (!comments.before.empty() || !comments.end.empty()) {
    app.sectionComments.push_back(std::move(comments));
  }
  if (name == "hosts") {
    detail::forEachChild(context, section, {"host"}, [&](const pugi::xml_node& child) {
      app.hosts.push_back(readHost(context, child));
    });
  } else if (name == "modules") {
    detail::forEachChild(context, section, {"module"}, [&](const pugi::xml_node& child) {
      app.modules.push_back(readModule(context, child));
    });
  } else if (name == "composites") {
    detail::readComposites(context, section, app);
  } else if (name == "instances") {
    detail::readInstances(context, section, app);
  } else if (name == "filters") {
    detail::forEachChild(context, section, {"filter"}, [&](const pugi::xml_node& child) {
      app.filters.push_back(readFilter(context, child));
    });
  } else if (name == "connections") {
    detail::forEachChild(context, section, {"connection"}, [&](const pugi::xml_node& child) {
      app.connections.push_back(readConnection(context, child));
    });
  } else {
    detail::readEditorSection(context, section, app);
  }
}

void readRoot(const ReadContext& context, const pugi::xml_node& root, Application& app) {
  const ElementReader reader(context, root, {"name", "version"});
  app.name = reader.text("name");
  app.comments = detail::commentsBefore(root);
  app.endComments = detail::trailingComments(root);
  app.afterComments = detail::commentsAfter(root);
  if (reader.has("version") && reader.text("version") != "1") {
    reader.errorAt("version", "unsupported format version '" + reader.text("version") +
                                  "' (this vrflow reads version 1)");
  }
  // Sections are optional but keep their order (as in the XSD); each appears once.
  std::size_t next = 0;
  detail::forEachChild(
      context, root, std::vector<std::string_view>(kSections.begin(), kSections.end()),
      [&](const pugi::xml_node& section) {
        std::size_t index = 0;
        while (kSections[index] != section.name()) ++index;
        const bool anotherFolder = index == 0 && next <= 1;
        if (index < next && !anotherFolder) {
          const bool repeated = index + 1 == next;
          context.error(context.source.element(section),
                        repeated ? "<" + std::string(section.name()) +
                                       "> appears twice; merge the two sections"
                                 : "<" + std::string(section.name()) +
                                       "> is out of order (sections go: packages, hosts, "
                                       "composites, modules, instances, filters, "
                                       "connections, editor)");
        }
        next = std::max(next, index + 1);
        readSection(context, section, app);
      });
}

// What the runtime relies on after loading: at least one host, and a host for everything.
void applyHostDefaults(Application& app) {
  if (app.hosts.empty()) {
    Host host;
    host.id = std::string(kDefaultHostId);
    host.address = std::string(kDefaultHostAddress);
    app.hosts.push_back(std::move(host));
  }
  const std::string& first = app.hosts.front().id;
  for (Module& module : app.modules) {
    if (module.host.empty()) module.host = first;
  }
  for (Filter& filter : app.filters) {
    if (filter.host.empty()) filter.host = first;
  }
  for (Instance& instance : app.instances) {
    if (instance.host.empty()) instance.host = first;
  }
}

}  // namespace

namespace detail {

std::optional<Application> readApplication(std::string_view xml, const std::string& fileName,
                                           std::vector<Diagnostic>& found) {
  const SourceText source(xml, fileName);
  Application app;
  app.file = fileName;
  const bool read = readDocument(source, "application", found,
                                 [&](const ReadContext& context, const pugi::xml_node& root) {
                                   readRoot(context, root, app);
                                 });
  if (!read) return std::nullopt;
  applyHostDefaults(app);
  return app;
}

}  // namespace detail

Result<Application> loadApplicationString(std::string_view xml, std::string fileName,
                                          std::vector<Diagnostic>* problems) {
  return detail::finishLoad<Application>(
      [&](std::vector<Diagnostic>& found) { return detail::readApplication(xml, fileName, found); },
      fileName, "application", problems);
}

Result<Application> loadApplicationFile(const std::string& path,
                                        std::vector<Diagnostic>* problems) {
  Result<std::string> content = detail::readWholeFile(path);
  if (!content) return makeError(path + ": error: " + content.error().message);
  return loadApplicationString(*content, path, problems);
}

}  // namespace vrflow::app
