#pragma once

#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/daemon/filter.hpp"

namespace vrflow::daemon::filters {

/// merge and gather: one message from every input, concatenated in input order; user stamps of
/// the first, or combined by the `stamps` rules. Also the merging step of a module's input.
class MergeFilter final : public Filter {
 public:
  explicit MergeFilter(std::vector<app::StampRule> rules = {}) : rules_(std::move(rules)) {}
  /// Keeps a reference to the last message emitted (lastEmitted()).
  void keepLast() { keepLast_ = true; }
  /// The last message emitted, when keepLast() was called and one was.
  const MessageRef* lastEmitted() const { return last_.valid() ? &last_ : nullptr; }

  void process(FilterContext& context) override;

 private:
  std::vector<MessageRef> parts_;
  std::vector<app::StampRule> rules_;
  bool keepLast_ = false;
  MessageRef last_;
};

}  // namespace vrflow::daemon::filters
