#include "vrflow/daemon/filter.hpp"

#include <cstdlib>

#include "builtin_filters.hpp"

namespace vrflow::daemon {

long FilterContext::paramInt(const std::string& key, long fallback) const {
  const std::string text = param(key, "");
  if (text.empty()) return fallback;
  char* end = nullptr;
  const long value = std::strtol(text.c_str(), &end, 10);
  return (end != nullptr && *end == '\0') ? value : fallback;
}

bool Filter::exhausted(FilterContext& context) const {
  for (std::size_t i = 0; i < context.inputCount(); ++i) {
    if (context.inputClosed(i) && context.input(i).empty()) return true;
  }
  return context.inputCount() == 0;
}

FilterRegistry& FilterRegistry::instance() {
  static FilterRegistry registry;
  return registry;
}

FilterRegistry::FilterRegistry() { registerBuiltinFilters(*this); }

void FilterRegistry::add(std::string type, FilterFactory factory) {
  factories_[std::move(type)] = std::move(factory);
}

const FilterFactory* FilterRegistry::find(const std::string& type) const {
  const auto it = factories_.find(type);
  return it == factories_.end() ? nullptr : &it->second;
}

}  // namespace vrflow::daemon
