#include "vrflow/daemon/filter.hpp"

#include <cmath>
#include <cstdlib>

#include "filters/filters.hpp"

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

Result<MessageRef> FilterContext::makeEmpty(uint64_t iteration, bool stampsOnly) {
  return compose(128, [&](msg::MessageBuilder& builder) {
    builder.setIteration(iteration);
    builder.setStampsOnly(stampsOnly);
  });
}

Result<MessageRef> FilterContext::concatenate(std::span<const MessageRef> parts) {
  return filters::join(*this, parts, {});
}

bool Filter::exhausted(FilterContext& context) const {
  for (std::size_t i = 0; i < context.inputCount(); ++i) {
    if (context.inputClosed(i) && context.input(i).empty()) return true;
  }
  return context.inputCount() == 0;
}

}  // namespace vrflow::daemon
