#include "vrflow/daemon/filter.hpp"

#include "builtin_filters.hpp"

namespace vrflow::daemon {

bool Filter::exhausted(FilterContext& context) const {
  for (std::size_t i = 0; i < context.inputCount(); ++i) {
    if (context.inputClosed(i) && context.input(i).empty()) return true;
  }
  return context.inputCount() == 0;
}

FilterRegistry& FilterRegistry::instance() {
  static FilterRegistry registry = [] {
    FilterRegistry builtins;
    registerBuiltinFilters(builtins);
    return builtins;
  }();
  return registry;
}

void FilterRegistry::add(std::string type, FilterFactory factory) {
  factories_[std::move(type)] = std::move(factory);
}

std::vector<std::string> FilterRegistry::types() const {
  std::vector<std::string> names;
  for (const auto& entry : factories_) names.push_back(entry.first);
  return names;
}

const FilterFactory* FilterRegistry::find(const std::string& type) const {
  const auto it = factories_.find(type);
  return it == factories_.end() ? nullptr : &it->second;
}

}  // namespace vrflow::daemon
