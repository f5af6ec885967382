// passthrough and broadcast: forward every message; initial: a few empty messages at start-up
// first (what starts a cycle of the network).
#include "filters.hpp"

namespace vrflow::daemon::filters {
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

FilterType passthroughType() {
  FilterType type;
  type.name = "passthrough";
  type.doc = "Forwards every message from in to out unchanged.";
  type.ports = inToOut;
  return type;
}

FilterType broadcastType() {
  FilterType type;
  type.name = "broadcast";
  type.doc =
      "Forwards every message from in to each connection of out; chain them as a tree to "
      "reach N receivers in O(log N) steps.";
  type.ports = inToOut;
  return type;
}

FilterType initialType() {
  FilterType type;
  type.name = "initial";
  type.doc =
      "Emits `count` empty messages on out at start-up, then forwards in to out; starts a "
      "cycle of the network.";
  const app::ParamSpec count = intParam("count", "1", 0, static_cast<double>(kMaxInitialMessages),
                                        "messages emitted at start-up");
  type.params.push_back(count);
  type.ports = inToOut;
  type.initialMessages = [count](const std::vector<Param>& params) {
    return static_cast<int>(clampedInt(count, params));
  };
  return type;
}

}  // namespace

void registerForward(FilterRegistry& registry) {
  addBuiltin(registry, {passthroughType(), factoryOf<PassthroughFilter>()});
  addBuiltin(registry, {broadcastType(), factoryOf<PassthroughFilter>()});
  addBuiltin(registry, {initialType(), factoryOf<InitialFilter>()});
}

}  // namespace vrflow::daemon::filters
