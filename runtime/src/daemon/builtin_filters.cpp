#include "builtin_filters.hpp"

#include <vector>

#include "filters/filters.hpp"

namespace vrflow::daemon {
namespace {

// Forwards each message of its single input as it comes.
void forwardAll(FilterContext& context) {
  auto& in = context.input(0);
  while (!in.empty() && context.canEmit(0)) {
    context.emit(0, std::move(in.front()));
    in.pop_front();
  }
}

class PassthroughFilter final : public Filter {
 public:
  void process(FilterContext& context) override { forwardAll(context); }
};

// Emits `count` empty messages at start so that a cycle can begin, then forwards.
class InitialFilter final : public Filter {
 public:
  Status start(FilterContext& context) override {
    pending_ = context.params().getInt("count");
    if (pending_ < 0) return makeError("filter '" + context.name() + "': count must be >= 0");
    return {};
  }
  void process(FilterContext& context) override {
    while (pending_ > 0 && context.canEmit(0)) {
      auto message = context.makeEmpty(static_cast<uint64_t>(emitted_++), false);
      if (!message) {
        context.warn(message.error().message);
        return;
      }
      context.emit(0, std::move(*message));
      --pending_;
    }
    if (pending_ == 0) forwardAll(context);
  }
  bool exhausted(FilterContext& context) const override {
    return pending_ == 0 && Filter::exhausted(context);
  }

 private:
  long pending_ = 0;
  long emitted_ = 0;
};

// One message from every input, concatenated in input order; user stamps of the first, or
// combined by the `stamps` rules.
class MergeFilter final : public Filter {
 public:
  explicit MergeFilter(std::vector<app::StampRule> rules = {}) : rules_(std::move(rules)) {}
  /// Keeps a reference to the last message emitted (lastEmitted()).
  void keepLast() { keepLast_ = true; }
  const MessageRef* lastEmitted() const { return last_.valid() ? &last_ : nullptr; }

  void process(FilterContext& context) override {
    const std::size_t n = context.inputCount();
    if (n == 0) return;  // nothing will ever arrive
    for (;;) {
      for (std::size_t i = 0; i < n; ++i) {
        if (context.input(i).empty()) return;
      }
      if (!context.canEmit(0)) return;
      parts_.clear();
      for (std::size_t i = 0; i < n; ++i) {
        parts_.push_back(std::move(context.input(i).front()));
        context.input(i).pop_front();
      }
      if (n == 1) {
        if (keepLast_) last_ = parts_.front();
        context.emit(0, std::move(parts_.front()));
        continue;
      }
      auto merged = filters::join(context, parts_, rules_);
      if (!merged) {
        context.warn(merged.error().message);
        continue;
      }
      if (keepLast_) last_ = *merged;
      context.emit(0, std::move(*merged));
    }
  }

 private:
  std::vector<MessageRef> parts_;
  std::vector<app::StampRule> rules_;
  bool keepLast_ = false;
  MessageRef last_;
};

Result<std::unique_ptr<Filter>> makeMerge(const FilterContext& context) {
  std::string problem;
  auto rules = app::parseStampRules(context.params().getString("stamps"), problem);
  if (!rules) return makeError("filter '" + context.name() + "': " + problem);
  return std::unique_ptr<Filter>(std::make_unique<MergeFilter>(std::move(*rules)));
}

// The default filter of a module's input port: initial messages first, then one message per
// incoming connection merged into one. `fifo` takes the oldest pending message of each
// connection (nothing is lost: a synchronous network keeps its data dependencies); `latest`
// keeps only the newest of each and never blocks the producers (greedy sampling); in a run that
// counts iterations, `latest` hands the last message again once every connection has ended,
// as long as the module runs, so that it reaches its count.
class PortInputFilter final : public Filter {
 public:
  Status start(FilterContext& context) override {
    initial_ = context.params().getInt("initial");
    latest_ = context.params().getString("mode") == "latest";
    if (latest_) merge_.keepLast();
    return {};
  }
  void process(FilterContext& context) override {
    while (initial_ > 0 && context.canEmit(0)) {
      auto message = context.makeEmpty(static_cast<uint64_t>(emittedInitial_++), false);
      if (!message) {
        context.warn(message.error().message);
        return;
      }
      context.emit(0, std::move(*message));
      --initial_;
    }
    if (initial_ > 0) return;
    if (!latest_) {
      merge_.process(context);
      return;
    }
    const std::size_t n = context.inputCount();
    if (newestIn_.size() != n) newestIn_.resize(n);
    bool anyPending = false;
    for (std::size_t i = 0; i < n; ++i) {
      auto& in = context.input(i);
      while (in.size() > 1) {
        in.pop_front();
        context.countDropped(i, 1, "replaced by a newer message");
      }
      if (!in.empty()) {
        newestIn_[i] = in.front();
        anyPending = true;
      }
    }
    // In a run that counts iterations, a connection whose producer has ended contributes its
    // newest message again, so the others' newer messages still reach the module.
    if (anyPending && context.runCountsIterations()) {
      for (std::size_t i = 0; i < n; ++i) {
        auto& in = context.input(i);
        if (in.empty() && context.inputClosed(i) && newestIn_[i].valid()) {
          in.push_back(newestIn_[i]);
        }
      }
    }
    merge_.process(context);
    if (const MessageRef* sent = merge_.lastEmitted()) last_ = *sent;
    // The ring holds at most one message: serve the last one again whenever the module took it.
    if (servesLastAfterEnd(context) && context.canEmit(0) && !context.outputEnded(0)) {
      context.emit(0, last_);
    }
  }
  bool exhausted(FilterContext& context) const override {
    if (initial_ != 0) return false;
    if (servesLastAfterEnd(context)) return context.outputEnded(0);
    return Filter::exhausted(context);
  }

 private:
  bool servesLastAfterEnd(FilterContext& context) const {
    return latest_ && last_.valid() && context.runCountsIterations() && Filter::exhausted(context);
  }
  long initial_ = 0;
  long emittedInitial_ = 0;
  bool latest_ = false;
  MessageRef last_;
  std::vector<MessageRef> newestIn_;  ///< latest mode: the newest message taken from each input
  MergeFilter merge_;
};

}  // namespace

void PortOutputFilter::process(FilterContext& context) {
  auto& in = context.input(0);
  while (!in.empty() && context.canEmit(0)) {
    last_ = in.front();
    ++forwarded_;
    context.emit(0, std::move(in.front()));
    in.pop_front();
  }
}

void registerBuiltinFilters(FilterRegistry& registry) {
  using filters::factoryOf;
  registry.add("passthrough", factoryOf<PassthroughFilter>());
  registry.add("broadcast", factoryOf<PassthroughFilter>());
  registry.add("initial", factoryOf<InitialFilter>());
  registry.add("merge", makeMerge);
  registry.add("gather", makeMerge);
  registry.add("port-input", factoryOf<PortInputFilter>());
  registry.add("port-output", factoryOf<PortOutputFilter>());
  filters::registerMultiplex(registry);
  filters::registerGate(registry);
  filters::registerRotate(registry);
  filters::registerScatter(registry);
  filters::registerLatest(registry);
  filters::registerMaxFrequency(registry);
  filters::registerStampFilter(registry);
  filters::registerTypeFilter(registry);
  filters::registerMultiRate(registry);
  filters::registerRoute(registry);
}

}  // namespace vrflow::daemon
