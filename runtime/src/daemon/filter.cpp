#include "vrflow/daemon/filter.hpp"

#include <cmath>
#include <cstdlib>

#include "filters/filters.hpp"

namespace vrflow::daemon {

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
