#include "composite_reader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <map>

#include "application_reader.hpp"
#include "file_io.hpp"
#include "source_text.hpp"
#include "template_text.hpp"
#include "text_util.hpp"
#include "validation.hpp"
#include "vrflow/app/composite_file.hpp"

namespace vrflow::app::detail {
namespace {

// <repeat> inside <repeat> deeper than this is refused (it would only be a hostile file).
constexpr int kMaxRepeatDepth = 16;

constexpr std::array<std::string_view, 4> kBodySections = {"modules", "instances", "filters",
                                                           "connections"};

// What each section holds (besides <repeat>).
std::string_view elementOf(std::string_view section) {
  if (section == "modules") return "module";
  if (section == "instances") return "instance";
  if (section == "filters") return "filter";
  return "connection";
}

// The attributes of a template element in canonical order, as ElementReader wants them.
ElementReader readerFor(const ReadContext& context, const pugi::xml_node& node) {
  const std::string_view name = node.name();
  if (name == "module") {
    return ElementReader(context, node, {"id", "package", "type", "host", "endit"});
  }
  if (name == "filter") return ElementReader(context, node, {"id", "type", "host"});
  if (name == "instance") return ElementReader(context, node, {"id", "composite", "host"});
  if (name == "connection") {
    return ElementReader(context, node, {"from", "to", "capacity", "policy"});
  }
  if (name == "param") return ElementReader(context, node, {"name", "value"});
  if (name == "input") return ElementReader(context, node, {"port", "initial-messages", "mode"});
  return ElementReader(context, node, {"var", "count", "start"});
}

struct TemplateShape {
  std::vector<const char*> attributes;  ///< canonical order
  std::vector<const char*> required;    ///< present and not empty
  std::vector<std::string_view> children;
};

TemplateShape shapeOf(std::string_view name, std::string_view sectionElement) {
  if (name == "module") {
    return {
        {"id", "package", "type", "host", "endit"}, {"id", "package", "type"}, {"param", "input"}};
  }
  if (name == "filter") return {{"id", "type", "host"}, {"id", "type"}, {"param"}};
  if (name == "instance") return {{"id", "composite", "host"}, {"id", "composite"}, {"param"}};
  if (name == "connection") return {{"from", "to", "capacity", "policy"}, {"from", "to"}, {}};
  if (name == "param") return {{"name", "value"}, {"name"}, {}};
  if (name == "input") return {{"port", "initial-messages", "mode"}, {"port"}, {}};
  return {{"var", "count", "start"}, {"var", "count"}, {sectionElement, "repeat"}};
}

TemplateElement readTemplate(const ReadContext& context, const pugi::xml_node& node,
                             std::string_view sectionElement, int repeatDepth) {
  const ElementReader reader = readerFor(context, node);
  const TemplateShape shape = shapeOf(node.name(), sectionElement);
  TemplateElement element;
  element.name = node.name();
  element.loc = reader.loc();
  for (const char* attribute : shape.attributes) {
    if (reader.has(attribute)) element.attributes.push_back({attribute, reader.text(attribute)});
  }
  for (const char* attribute : shape.required) (void)reader.required(attribute);
  if (element.name == "param" && !reader.has("value")) {
    context.error(reader.loc(), missingAttributeMessage("param", "value"));
  }
  if (element.name == "repeat") {
    const std::string var = reader.text("var");
    if (!var.empty() && !isTemplateName(var)) {
      reader.errorAt("var", "repeat variable '" + var +
                                "' must be a name: a letter or '_', then letters, digits, '_'");
    }
    if (var == kInstanceTemplateName) {
      reader.errorAt("var", "repeat variable '" + var +
                                "' is reserved: ${instance} is the id of the instance being "
                                "expanded; choose another name");
    }
    if (repeatDepth >= kMaxRepeatDepth) {
      context.error(reader.loc(),
                    "<repeat> is nested more than " + std::to_string(kMaxRepeatDepth) + " deep");
      return element;
    }
  }
  const int childDepth = element.name == "repeat" ? repeatDepth + 1 : repeatDepth;
  forEachChild(context, node, shape.children, [&](const pugi::xml_node& child) {
    element.children.push_back(readTemplate(context, child, sectionElement, childDepth));
  });
  return element;
}

// Bounds of a parameter: integers; a default must then be an integer in range too.
std::optional<long long> readBound(const ElementReader& reader, const char* attribute) {
  if (!reader.has(attribute)) return std::nullopt;
  const std::string text = reader.text(attribute);
  const std::optional<long long> value = parseInteger(text);
  if (!value) {
    reader.errorAt(attribute, "attribute '" + std::string(attribute) +
                                  "' of <param> must be an integer, got '" + text + "'");
  }
  return value;
}

CompositeParam readCompositeParam(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node, {"name", "default", "min", "max", "doc"});
  CompositeParam param;
  param.name = reader.required("name");
  if (!param.name.empty() && !isTemplateName(param.name)) {
    reader.errorAt("name", "parameter name '" + param.name +
                               "' must be a name: a letter or '_', then letters, digits, '_'");
  }
  if (param.name == kInstanceTemplateName) {
    reader.errorAt("name", "parameter name '" + param.name +
                               "' is reserved: ${instance} is the id of the instance being "
                               "expanded; choose another name");
  }
  if (reader.has("default")) param.defaultValue = reader.text("default");
  param.min = readBound(reader, "min");
  param.max = readBound(reader, "max");
  param.doc = reader.text("doc");
  param.loc = reader.loc();
  if (param.min && param.max && *param.min > *param.max) {
    reader.errorAt(
        "max", "max " + std::to_string(*param.max) + " is below min " + std::to_string(*param.min));
  }
  if (param.defaultValue && (param.min || param.max)) {
    const std::optional<long long> value = parseInteger(*param.defaultValue);
    if (!value || (param.min && *value < *param.min) || (param.max && *value > *param.max)) {
      reader.errorAt("default", "default '" + *param.defaultValue +
                                    "' is not an integer within the parameter's min and max");
    }
  }
  forEachChild(context, node, {}, [](const pugi::xml_node&) {});
  return param;
}

CompositePort readPort(const ReadContext& context, const pugi::xml_node& node, bool input) {
  const char* endpoint = input ? "to" : "from";
  const ElementReader reader(context, node, {"name", endpoint, "doc"});
  CompositePort port;
  port.name = reader.required("name");
  if (port.name.find('.') != std::string::npos) {
    reader.errorAt("name", "port name '" + port.name + "' must not contain '.'");
  }
  port.endpoint = reader.required(endpoint);
  port.doc = reader.text("doc");
  port.loc = reader.loc();
  forEachChild(context, node, {}, [](const pugi::xml_node&) {});
  return port;
}

// Names of composites become file names (NAME.vrc.xml).
bool isCompositeName(std::string_view name) {
  return !name.empty() && name.front() != '-' && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-';
  });
}

// Parameters and ports are declared once each; ports share one namespace.
void checkDeclarations(const ReadContext& context, const Composite& composite) {
  std::map<std::string, const SourceLocation*, std::less<>> params;
  for (const CompositeParam& param : composite.params) {
    const auto [it, added] = params.emplace(param.name, &param.loc);
    if (!added && !param.name.empty()) {
      context.error(
          param.loc.attribute("name"),
          "parameter '" + param.name + "' is declared twice (first" + atLine(*it->second) + ")");
    }
  }
  std::map<std::string, const SourceLocation*, std::less<>> ports;
  for (const auto* list : {&composite.inputs, &composite.outputs}) {
    for (const CompositePort& port : *list) {
      const auto [it, added] = ports.emplace(port.name, &port.loc);
      if (!added && !port.name.empty()) {
        context.error(
            port.loc.attribute("name"),
            "port '" + port.name + "' is declared twice (first" + atLine(*it->second) + ")");
      }
    }
  }
}

std::vector<TemplateElement>& sectionOf(Composite& composite, std::string_view name) {
  if (name == "modules") return composite.modules;
  if (name == "instances") return composite.instances;
  if (name == "filters") return composite.filters;
  return composite.connections;
}

void readBody(const ReadContext& context, const pugi::xml_node& node, Composite& composite) {
  std::size_t next = 0;
  forEachChild(
      context, node, {"param", "input", "output", "modules", "instances", "filters", "connections"},
      [&](const pugi::xml_node& child) {
        const std::string_view name = child.name();
        if (name == "param") {
          composite.params.push_back(readCompositeParam(context, child));
        } else if (name == "input" || name == "output") {
          (name == "input" ? composite.inputs : composite.outputs)
              .push_back(readPort(context, child, name == "input"));
        } else {
          std::size_t index = 0;
          while (kBodySections[index] != name) ++index;
          if (index < next) {
            context.error(context.source.element(child),
                          index + 1 == next
                              ? "<" + std::string(name) + "> appears twice; merge the two sections"
                              : "<" + std::string(name) +
                                    "> is out of order (a composite's sections go: modules, "
                                    "instances, filters, connections)");
          }
          next = std::max(next, index + 1);
          const ElementReader sectionReader(context, child, {});
          const std::string_view element = elementOf(name);
          forEachChild(context, child, {element, "repeat"}, [&](const pugi::xml_node& item) {
            sectionOf(composite, name).push_back(readTemplate(context, item, element, 0));
          });
        }
      });
}

Composite readComposite(const ReadContext& context, const pugi::xml_node& node, bool standalone) {
  const ElementReader reader = standalone ? ElementReader(context, node, {"name", "version", "doc"})
                                          : ElementReader(context, node, {"name", "doc"});
  Composite composite;
  composite.name = reader.required("name");
  if (!composite.name.empty() && !isCompositeName(composite.name)) {
    reader.errorAt("name", "composite name '" + composite.name +
                               "' may hold only letters, digits, '_' and '-' (its file is "
                               "NAME.vrc.xml)");
  }
  if (standalone && reader.has("version") && reader.text("version") != "1") {
    reader.errorAt("version", "unsupported format version '" + reader.text("version") +
                                  "' (this vrflow reads version 1)");
  }
  composite.doc = reader.text("doc");
  composite.loc = reader.loc();
  readBody(context, node, composite);
  checkDeclarations(context, composite);
  return composite;
}

Instance readInstance(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node, {"id", "composite", "host"});
  Instance instance;
  instance.id = reader.required("id");
  instance.composite = reader.required("composite");
  instance.host = reader.text("host");
  instance.loc = reader.loc();
  instance.comments = commentsBefore(node);
  forEachChild(context, node, {"param"}, [&](const pugi::xml_node& child) {
    instance.params.push_back(readParam(context, child));
  });
  return instance;
}

}  // namespace

void readComposites(const ReadContext& context, const pugi::xml_node& section, Application& app) {
  const ElementReader reader(context, section, {});
  forEachChild(context, section, {"composite"}, [&](const pugi::xml_node& child) {
    Composite composite = readComposite(context, child, false);
    if (const Composite* first = findComposite(app, composite.name);
        first != nullptr && !composite.name.empty()) {
      context.error(
          composite.loc.attribute("name"),
          "composite '" + composite.name + "' is defined twice (first" + atLine(first->loc) + ")");
    }
    app.composites.push_back(std::move(composite));
  });
}

void readInstances(const ReadContext& context, const pugi::xml_node& section, Application& app) {
  const ElementReader reader(context, section, {});
  forEachChild(context, section, {"instance"}, [&](const pugi::xml_node& child) {
    app.instances.push_back(readInstance(context, child));
  });
}

std::optional<Composite> readCompositeFile(std::string_view xml, const std::string& fileName,
                                           std::vector<Diagnostic>& problems) {
  const SourceText source(xml, fileName);
  Composite composite;
  const bool read = readDocument(source, "composite", problems,
                                 [&](const ReadContext& context, const pugi::xml_node& root) {
                                   composite = readComposite(context, root, true);
                                 });
  if (!read) return std::nullopt;
  return composite;
}

}  // namespace vrflow::app::detail

namespace vrflow::app {

Result<Composite> loadCompositeString(std::string_view xml, std::string fileName,
                                      std::vector<Diagnostic>* problems) {
  return detail::finishLoad<Composite>(
      [&](std::vector<Diagnostic>& found) {
        return detail::readCompositeFile(xml, fileName, found);
      },
      fileName, "composite", problems);
}

Result<Composite> loadCompositeFile(const std::string& path, std::vector<Diagnostic>* problems) {
  Result<std::string> content = detail::readWholeFile(path);
  if (!content) return makeError(path + ": error: " + content.error().message);
  return loadCompositeString(*content, path, problems);
}

}  // namespace vrflow::app
