#pragma once

#include "vrflow/daemon/filter_registry.hpp"

namespace vrflow::daemon {

/// The default filter of a module's output port: forwards every message to all connections and
/// remembers the last one (for the run report's digest).
class PortOutputFilter final : public Filter {
 public:
  void process(FilterContext& context) override;
  const MessageRef& last() const { return last_; }
  uint64_t forwarded() const { return forwarded_; }

 private:
  MessageRef last_;
  uint64_t forwarded_ = 0;
};

/// Registers the built-in filter types; called once by FilterRegistry::instance().
void registerBuiltinFilters(FilterRegistry& registry);

}  // namespace vrflow::daemon
