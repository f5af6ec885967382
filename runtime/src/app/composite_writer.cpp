#include "composite_writer.hpp"

#include "file_io.hpp"
#include "vrflow/app/composite_file.hpp"
#include "xml_out.hpp"

namespace vrflow::app {
namespace detail {
namespace {

// Template elements keep what was written: every attribute, in the order the reader stored
// (the element's canonical order), no default left out.
void writeTemplate(std::string& out, int depth, const TemplateElement& element) {
  Tag tag(out, depth, element.name);
  for (const TemplateAttribute& attribute : element.attributes) {
    tag.attribute(attribute.name, attribute.value);
  }
  if (element.children.empty()) {
    tag.close();
    return;
  }
  tag.open();
  for (const TemplateElement& child : element.children) writeTemplate(out, depth + 1, child);
  closeTag(out, depth, element.name);
}

void writeSection(std::string& out, int depth, const char* name,
                  const std::vector<TemplateElement>& elements) {
  if (elements.empty()) return;
  Tag(out, depth, name).open();
  for (const TemplateElement& element : elements) writeTemplate(out, depth + 1, element);
  closeTag(out, depth, name);
}

void writePorts(std::string& out, int depth, const char* element, const char* endpoint,
                const std::vector<CompositePort>& ports) {
  for (const CompositePort& port : ports) {
    Tag(out, depth, element)
        .attribute("name", port.name)
        .attribute(endpoint, port.endpoint)
        .attributeUnless("doc", port.doc, "")
        .close();
  }
}

// A standalone file's root also says which version of the format it is written in.
void writeComposite(std::string& out, int depth, const Composite& composite, bool standalone) {
  Tag root(out, depth, "composite");
  root.attribute("name", composite.name);
  if (standalone) root.attribute("version", "1");
  root.attributeUnless("doc", composite.doc, "");
  const bool empty = composite.params.empty() && composite.inputs.empty() &&
                     composite.outputs.empty() && composite.modules.empty() &&
                     composite.instances.empty() && composite.filters.empty() &&
                     composite.connections.empty();
  if (empty) {
    root.close();
    return;
  }
  root.open();
  for (const CompositeParam& param : composite.params) {
    Tag tag(out, depth + 1, "param");
    tag.attribute("name", param.name);
    if (param.defaultValue) tag.attribute("default", *param.defaultValue);
    if (param.min) tag.attribute("min", std::to_string(*param.min));
    if (param.max) tag.attribute("max", std::to_string(*param.max));
    tag.attributeUnless("doc", param.doc, "").close();
  }
  writePorts(out, depth + 1, "input", "to", composite.inputs);
  writePorts(out, depth + 1, "output", "from", composite.outputs);
  writeSection(out, depth + 1, "modules", composite.modules);
  writeSection(out, depth + 1, "instances", composite.instances);
  writeSection(out, depth + 1, "filters", composite.filters);
  writeSection(out, depth + 1, "connections", composite.connections);
  closeTag(out, depth, "composite");
}

}  // namespace

void writeComposites(std::string& out, const Application& app) {
  if (app.composites.empty()) return;
  openSection(out, app, "composites");
  for (const Composite& composite : app.composites) writeComposite(out, 2, composite, false);
  closeSection(out, app, "composites");
}

void writeInstances(std::string& out, const Application& app) {
  if (app.instances.empty()) return;
  const std::string firstHost = app.hosts.empty() ? std::string() : app.hosts.front().id;
  openSection(out, app, "instances");
  for (const Instance& instance : app.instances) {
    writeComments(out, 2, instance.comments);
    Tag tag(out, 2, "instance");
    tag.attribute("id", instance.id).attribute("composite", instance.composite);
    if (!instance.host.empty()) tag.attributeUnless("host", instance.host, firstHost);
    if (instance.params.empty()) {
      tag.close();
      continue;
    }
    tag.open();
    writeParams(out, 3, instance.params);
    closeTag(out, 2, "instance");
  }
  closeSection(out, app, "instances");
}

}  // namespace detail

std::string saveComposite(const Composite& composite) {
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  detail::writeComposite(out, 0, composite, true);
  return out;
}

Status saveCompositeFile(const Composite& composite, const std::string& path) {
  try {
    return detail::writeWholeFile(path, saveComposite(composite));
  } catch (const std::exception& e) {
    return makeError(path + ": error: cannot save composite (" + e.what() + ")");
  }
}

}  // namespace vrflow::app
