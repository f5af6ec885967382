#include "vrflow/daemon/filter_registry.hpp"

#include "builtin_filters.hpp"
#include "vrflow/base/assert.hpp"

namespace vrflow::daemon {

FilterRegistry& FilterRegistry::instance() {
  static FilterRegistry registry = [] {
    FilterRegistry builtins;
    registerBuiltinFilters(builtins);
    return builtins;
  }();
  return registry;
}

Status FilterRegistry::add(FilterSpec spec) {
  if (spec.name().empty()) return makeError("a filter type has an empty name");
  if (!spec.factory) return makeError("filter type '" + spec.name() + "' has no factory");
  if (specs_.count(spec.name()) != 0) {
    return makeError("filter type '" + spec.name() +
                     "' exists already (built in or from another plugin)");
  }
  std::string name = spec.name();
  specs_.emplace(std::move(name), std::move(spec));
  return {};
}

const FilterSpec* FilterRegistry::find(const std::string& type) const {
  const auto it = specs_.find(type);
  return it == specs_.end() ? nullptr : &it->second;
}

std::vector<std::string> FilterRegistry::types() const {
  std::vector<std::string> names;
  for (const auto& entry : specs_) names.push_back(entry.first);
  return names;
}

void FilterRegistry::addTo(app::Catalog& catalog) const {
  for (const auto& [name, spec] : specs_) {
    if (!spec.inCatalog || catalog.findFilter(name) != nullptr) continue;
    const Status added = catalog.addFilterType(spec.declaration);
    VRFLOW_ASSERT(added.ok(), "a filter type absent from the catalog is added to it");
  }
}

app::Catalog makeCatalog() {
  app::Catalog catalog;
  FilterRegistry::instance().addTo(catalog);
  return catalog;
}

}  // namespace vrflow::daemon
