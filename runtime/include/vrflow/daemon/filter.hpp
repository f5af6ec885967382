#pragma once

#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/daemon/message_ref.hpp"

namespace vrflow::daemon {

/// What a filter sees: the messages buffered on its inputs, and outputs to emit on.
/// Filters run on the daemon's thread; they never block.
class FilterContext {
 public:
  virtual ~FilterContext() = default;

  /// The filter's id (for messages) and its parameters from the application file.
  virtual const std::string& name() const = 0;
  virtual std::string param(const std::string& key, const std::string& fallback) const = 0;
  long paramInt(const std::string& key, long fallback) const;

  virtual std::size_t inputCount() const = 0;
  /// Messages buffered on input `i`, oldest first. Pop what you consume.
  virtual std::deque<MessageRef>& input(std::size_t i) = 0;
  /// True when input `i` will never receive another message (its buffer may still hold some).
  virtual bool inputClosed(std::size_t i) const = 0;

  virtual std::size_t outputCount() const = 0;
  /// True when every destination of output `o` can take one more message now.
  virtual bool canEmit(std::size_t o) const = 0;
  /// Sends a message to every destination of output `o`.
  virtual void emit(std::size_t o, MessageRef message) = 0;

  /// A new message with no chunk (for initial messages and signals).
  virtual Result<MessageRef> makeEmpty(uint64_t iteration, bool stampsOnly) = 0;
  /// A new message holding the chunks of `parts` in order; stamps from the first, the
  /// iteration and simulation time the largest among them.
  virtual Result<MessageRef> concatenate(std::span<const MessageRef> parts) = 0;
  /// Reports a problem with the data flowing through this filter (logged; the run goes on).
  virtual void warn(const std::string& message) = 0;
};

/// A filter: runs inside the daemon, sees every message buffered on its inputs, emits any
/// messages. Write one by deriving from this class and registering a factory (see
/// FilterRegistry); the daemon calls process() whenever something may have changed.
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

using FilterFactory = std::function<Result<std::unique_ptr<Filter>>(const FilterContext&)>;

/// Filter types by name. Built-ins: passthrough, merge, initial, broadcast, and the default
/// per-port filters `port-input` and `port-output`.
class FilterRegistry {
 public:
  static FilterRegistry& instance();
  void add(std::string type, FilterFactory factory);
  const FilterFactory* find(const std::string& type) const;

 private:
  FilterRegistry();
  std::map<std::string, FilterFactory> factories_;
};

}  // namespace vrflow::daemon
