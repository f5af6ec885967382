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
    pending_ = context.paramInt("count", 1);
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

// One message from every input, concatenated in input order.
class MergeFilter final : public Filter {
 public:
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
        context.emit(0, std::move(parts_.front()));
        continue;
      }
      auto merged = context.concatenate(parts_);
      if (!merged) {
        context.warn(merged.error().message);
        continue;
      }
      context.emit(0, std::move(*merged));
    }
  }

 protected:
  std::vector<MessageRef> parts_;
};

// The default filter of a module's input port: initial messages first, then one message per
// incoming connection merged into one. `fifo` takes the oldest pending message of each
// connection (nothing is lost: a synchronous network keeps its data dependencies); `latest`
// keeps only the newest of each and never blocks the producers (greedy sampling).
class PortInputFilter final : public Filter {
 public:
  Status start(FilterContext& context) override {
    initial_ = context.paramInt("initial", 0);
    latest_ = context.param("mode", "fifo") == "latest";
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
    if (latest_) {
      for (std::size_t i = 0; i < context.inputCount(); ++i) {
        auto& in = context.input(i);
        while (in.size() > 1) in.pop_front();
      }
    }
    merge_.process(context);
  }
  bool exhausted(FilterContext& context) const override {
    return initial_ == 0 && Filter::exhausted(context);
  }

 private:
  long initial_ = 0;
  long emittedInitial_ = 0;
  bool latest_ = false;
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
  registry.add("merge", factoryOf<MergeFilter>());
  registry.add("gather", factoryOf<MergeFilter>());
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
