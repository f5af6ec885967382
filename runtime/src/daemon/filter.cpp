#include "vrflow/daemon/filter.hpp"

#include <cmath>
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

double FilterContext::paramFloat(const std::string& key, double fallback) const {
  const std::string text = param(key, "");
  if (text.empty()) return fallback;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  return (end != nullptr && *end == '\0' && std::isfinite(value)) ? value : fallback;
}

bool FilterContext::paramBool(const std::string& key, bool fallback) const {
  const std::string text = param(key, "");
  if (text == "true" || text == "1") return true;
  if (text == "false" || text == "0") return false;
  return fallback;
}

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
