#include "vrflow/app/composite.hpp"

#include <algorithm>

#include "vrflow/app/model.hpp"

namespace vrflow::app {

const std::string* TemplateElement::find(std::string_view attribute) const {
  for (const TemplateAttribute& written : attributes) {
    if (written.name == attribute) return &written.value;
  }
  return nullptr;
}

const CompositeParam* findCompositeParam(const Composite& composite, std::string_view name) {
  const auto it = std::find_if(composite.params.begin(), composite.params.end(),
                               [&](const CompositeParam& param) { return param.name == name; });
  return it == composite.params.end() ? nullptr : &*it;
}

const CompositePort* findCompositePort(const std::vector<CompositePort>& ports,
                                       std::string_view name) {
  const auto it = std::find_if(ports.begin(), ports.end(),
                               [&](const CompositePort& port) { return port.name == name; });
  return it == ports.end() ? nullptr : &*it;
}

const Instance* findInstance(const Application& app, std::string_view id) {
  const auto it = std::find_if(app.instances.begin(), app.instances.end(),
                               [&](const Instance& instance) { return instance.id == id; });
  return it == app.instances.end() ? nullptr : &*it;
}

const Composite* findComposite(const Application& app, std::string_view name) {
  const auto it = std::find_if(app.composites.begin(), app.composites.end(),
                               [&](const Composite& composite) { return composite.name == name; });
  return it == app.composites.end() ? nullptr : &*it;
}

}  // namespace vrflow::app
