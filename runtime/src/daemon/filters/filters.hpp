#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/daemon/filter_registry.hpp"
#include "vrflow/message/reader.hpp"

// The standard filter library (docs/filters.md): one register function per file, adding the
// FilterSpec of each type the file implements (its declaration beside its code).

namespace vrflow::daemon::filters {

using app::FilterType;
using app::Param;
using app::paramString;
using app::PortSpec;
using app::splitList;

/// kMaxFilterPorts as the bound of a parameter.
inline constexpr double kMaxPorts = static_cast<double>(kMaxFilterPorts);

/// Adds a built-in filter type to `registry` (a bug when its name is taken).
void addBuiltin(FilterRegistry& registry, FilterSpec spec);

void registerForward(FilterRegistry& registry);  ///< passthrough, broadcast and initial
void registerMerge(FilterRegistry& registry);    ///< merge and gather

void registerMultiplex(FilterRegistry& registry);
void registerGate(FilterRegistry& registry);
void registerRotate(FilterRegistry& registry);  ///< rotate and unrotate
void registerScatter(FilterRegistry& registry);
void registerLatest(FilterRegistry& registry);
void registerMaxFrequency(FilterRegistry& registry);
void registerStampFilter(FilterRegistry& registry);
void registerTypeFilter(FilterRegistry& registry);
void registerMultiRate(FilterRegistry& registry);  ///< repeat and decimate
void registerRoute(FilterRegistry& registry);

/// A factory for a filter built without arguments.
template <typename T>
FilterFactory factoryOf() {
  return [](const FilterContext&) -> Result<std::unique_ptr<Filter>> {
    return std::unique_ptr<Filter>(std::make_unique<T>());
  };
}

/// Emits the empty initial messages still `pending` on output 0 while it can take them,
/// numbering them from `emitted` (both counted down / up). False when one could not be made
/// (warned): try again on the next pass.
bool emitInitialMessages(FilterContext& context, long& pending, long& emitted);

/// True when every input is closed and drained (for filters that go on while any input may
/// still bring something).
bool allInputsDone(FilterContext& context);

/// The message's parsed view, or nullopt after warning that it is malformed.
std::optional<msg::MessageView> viewOrWarn(FilterContext& context, const MessageRef& message);

/// One message joining `parts`: their chunks in order, the stamps of the first (user stamps
/// included), the largest iteration and simulation time; each of `rules` combines a user stamp
/// over the parts that carry it (FilterContext::concatenate is join with no rule).
Result<MessageRef> join(FilterContext& context, std::span<const MessageRef> parts,
                        const std::vector<app::StampRule>& rules);

/// A copy of `message` (stamps, flag, chunks) with its iteration stamp replaced.
Result<MessageRef> restamp(FilterContext& context, const msg::MessageView& message,
                           uint64_t iteration);

/// Remembers the iteration stamp of the message at the head of one input, so that a filter
/// that looks at it on every pass parses it once. It holds a reference to that message, so
/// its block cannot be reused for another message while remembered.
class HeadIteration {
 public:
  /// The iteration of `message`, or nullopt (after a warning) when it is malformed.
  std::optional<uint64_t> of(FilterContext& context, const MessageRef& message);

 private:
  MessageRef message_;
  uint64_t iteration_ = 0;
};

}  // namespace vrflow::daemon::filters
