#pragma once

#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "vrflow/base/parameters.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/daemon/message_ref.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::daemon {

/// What a filter sees: the messages buffered on its inputs, and outputs to emit on.
/// Filters run on the daemon's thread; they never block.
class FilterContext {
 public:
  virtual ~FilterContext() = default;

  /// The filter's id (for messages) and its parameters from the application file.
  virtual const std::string& name() const = 0;
  /// The typed parameters: the file's values over the filter spec's defaults. Reading one the
  /// spec does not declare, or as another type, is an error the daemon reports (naming the
  /// filter and the parameter) once the factory or start() returns: the run does not start.
  virtual const Parameters& params() const = 0;

  virtual std::size_t inputCount() const = 0;
  /// Messages buffered on input `i`, oldest first. Pop what you consume.
  virtual std::deque<MessageRef>& input(std::size_t i) = 0;
  /// True when input `i` will never receive another message (its buffer may still hold some).
  virtual bool inputClosed(std::size_t i) const = 0;
  /// Counts `count` messages of input `i` that the filter consumed without passing them on
  /// (whole or merged into what it emits), for the run report's per-port counters; `reason`
  /// says why in a few words ("gate closed", "replaced by a newer message").
  virtual void countDropped(std::size_t i, uint64_t count, std::string_view reason) = 0;

  virtual std::size_t outputCount() const = 0;
  /// True when every destination of output `o` can take one more message now.
  virtual bool canEmit(std::size_t o) const = 0;
  /// Sends a message to every destination of output `o`.
  virtual void emit(std::size_t o, MessageRef message) = 0;
  /// True when output `o` has destinations and every one of them is a module that has ended
  /// (it takes and drops everything): emitting there is pointless.
  virtual bool outputEnded(std::size_t o) const = 0;
  /// True when the run gives every module an iteration count (`--iterations`). Sampling filters
  /// then serve their newest message again after their data has ended, so that their consumer
  /// reaches its count (docs/filters.md).
  virtual bool runCountsIterations() const = 0;
  /// When the run is traced, records which parts a joined message was made of (the trace's
  /// arrows); a context that does not trace ignores it.
  virtual void recordMerge(std::span<const msg::MessageView> views) { (void)views; }

  /// A new message with no chunk (for initial messages and signals), made with compose().
  Result<MessageRef> makeEmpty(uint64_t iteration, bool stampsOnly);
  /// A new message holding the chunks of `parts` in order; stamps from the first, the
  /// iteration and simulation time the largest among them.
  Result<MessageRef> concatenate(std::span<const MessageRef> parts);
  /// A new message written by `fill` straight into shared memory (`sizeHint` bytes reserved up
  /// front; the block grows as needed). The builder starts with this filter as the source;
  /// `fill` may replace every stamp (setStamps) and copy chunks (appendChunk, appendChunks).
  /// Fails when shared memory is exhausted.
  virtual Result<MessageRef> compose(std::size_t sizeHint,
                                     const std::function<void(msg::MessageBuilder&)>& fill) = 0;

  /// Monotonic clock, ns (the clock wakeAfter counts on).
  virtual uint64_t nowNs() const = 0;
  /// Asks the daemon to call process() again once `delayNs` have passed, even if no message
  /// moves (a timer; it may come earlier, when something else happens). The request holds
  /// until the next call of process(): ask again there while the filter still waits.
  virtual void wakeAfter(uint64_t delayNs) = 0;
  /// Reports a problem with the data flowing through this filter (logged; the run goes on).
  virtual void warn(const std::string& message) = 0;
};

/// A filter: runs inside the daemon, sees every message buffered on its inputs, emits any
/// messages. Write one by deriving from this class and declaring its type with a FilterSpec
/// (vrflow/daemon/filter_spec.hpp); the daemon calls process() whenever something may have
/// changed.
class Filter {
 public:
  virtual ~Filter() = default;
  /// Called once before any message flows (e.g. to emit initial messages).
  virtual Status start(FilterContext& /*context*/) { return {}; }
  /// Consumes buffered messages and emits results; must not block.
  virtual void process(FilterContext& context) = 0;
  /// True when this filter will never emit again (its outputs are then closed). The default:
  /// some input is closed and drained, since most filters need a message on every input.
  virtual bool exhausted(FilterContext& context) const;
};

/// Makes a filter for one node of the network. It may read the node's name, parameters and
/// port counts (not its queues); an error (a parameter it cannot use) stops the run's start.
using FilterFactory = std::function<Result<std::unique_ptr<Filter>>(const FilterContext&)>;

}  // namespace vrflow::daemon
