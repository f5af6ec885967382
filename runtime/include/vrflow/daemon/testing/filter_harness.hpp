#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/daemon/filter_spec.hpp"
#include "vrflow/ipc/segment.hpp"

namespace vrflow::daemon::testing {

/// Runs one filter in-process, without a daemon, for unit tests (of the built-in filters and of
/// plugins' filters): it is the filter's FilterContext. Feed messages to its inputs, step it,
/// read what it emitted on each output. Messages live in a shared-memory segment of its own;
/// those a test keeps must not outlive the harness. Time is a clock the test advances.
class FilterHarness final : public FilterContext {
 public:
  /// Builds filter `type` of FilterRegistry::instance() named `type`, with `params` over its
  /// declared defaults, and starts it. The parameters are checked as `vrflow validate` checks a
  /// filter (each against its declaration, then the type's rule over them); the filter's ports
  /// are its declaration's for these parameters. Fails with the first problem's message: an
  /// unknown type or parameter, a bad value, the type's rule, its factory's or start()'s error.
  static Result<std::unique_ptr<FilterHarness>> create(
      const std::string& type, const std::map<std::string, std::string>& params = {});

  FilterHarness(const FilterHarness&) = delete;
  FilterHarness& operator=(const FilterHarness&) = delete;
  ~FilterHarness() override;

  /// A message from source "test", built by `fill` (stamps, chunks); empty when `fill` is.
  MessageRef message(const std::function<void(msg::MessageBuilder&)>& fill = {});
  /// An empty message with iteration stamp `iteration`.
  MessageRef stamped(uint64_t iteration);
  /// Appends `message` to input `port` (a bug when the filter has no such input).
  void push(std::string_view port, MessageRef message);
  /// Input `port` will never receive another message (what it holds stays).
  void close(std::string_view port);
  /// Runs the filter's process() once.
  void step();
  /// True when the filter says it will never emit again.
  bool exhausted();

  /// The messages emitted on output `port` since the last take, oldest first.
  std::vector<MessageRef> take(std::string_view port);
  /// The iteration stamps of take(port).
  std::vector<uint64_t> takeIterations(std::string_view port);
  /// Output `port` takes `room` more messages, then canEmit() is false until it gets more
  /// (unlimited when never called): a full destination.
  void setRoom(std::string_view port, std::size_t room);
  /// Every destination of output `port` is a module that has ended (outputEnded()).
  void endOutput(std::string_view port);
  /// The run gives every module an iteration count (runCountsIterations()).
  void setRunCountsIterations(bool counts) { countsIterations_ = counts; }
  /// Moves the clock nowNs() reads forward.
  void advanceClock(uint64_t ns) { clockNs_ += ns; }
  /// The delay the last step asked to be called again after (wakeAfter()), if it asked.
  std::optional<uint64_t> wakeDelay() const { return wakeDelay_; }
  /// Everything the filter warned about, oldest first.
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// How many messages of input `port` the filter consumed without passing them on.
  uint64_t droppedOn(std::string_view port) const;
  /// The input and output port names, in the filter's order.
  const std::vector<std::string>& inputNames() const { return inputNames_; }
  const std::vector<std::string>& outputNames() const { return outputNames_; }

  // FilterContext, as the daemon offers it.
  const std::string& name() const override { return name_; }
  const Parameters& params() const override { return params_; }
  std::size_t inputCount() const override { return inputs_.size(); }
  std::deque<MessageRef>& input(std::size_t i) override { return inputs_.at(i); }
  bool inputClosed(std::size_t i) const override { return closed_.at(i); }
  void countDropped(std::size_t i, uint64_t count, std::string_view reason) override;
  std::size_t outputCount() const override { return outputs_.size(); }
  bool canEmit(std::size_t o) const override;
  void emit(std::size_t o, MessageRef message) override;
  bool outputEnded(std::size_t o) const override { return ended_.at(o); }
  bool runCountsIterations() const override { return countsIterations_; }
  Result<MessageRef> compose(std::size_t sizeHint,
                             const std::function<void(msg::MessageBuilder&)>& fill) override;
  uint64_t nowNs() const override { return clockNs_; }
  void wakeAfter(uint64_t delayNs) override;
  void warn(const std::string& message) override { warnings_.push_back(message); }

 private:
  FilterHarness(ipc::Segment segment, std::string type, Parameters params,
                const std::vector<app::PortSpec>& ports);
  std::size_t inputIndex(std::string_view port) const;
  std::size_t outputIndex(std::string_view port) const;

  ipc::Segment segment_;  ///< first: every message below is released before it goes
  std::string name_;
  Parameters params_;
  std::vector<std::string> inputNames_, outputNames_;
  std::vector<std::deque<MessageRef>> inputs_;
  std::vector<bool> closed_;
  std::vector<uint64_t> dropped_;
  std::vector<std::vector<MessageRef>> outputs_;
  std::vector<std::optional<std::size_t>> room_;
  std::vector<bool> ended_;
  bool countsIterations_ = false;
  uint64_t clockNs_ = 1'000'000'000;
  std::optional<uint64_t> wakeDelay_;
  std::vector<std::string> warnings_;
  std::unique_ptr<Filter> filter_;  ///< last: it goes first
};

}  // namespace vrflow::daemon::testing
