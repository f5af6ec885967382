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
    pending_ = context.params().getInt("count");
    if (pending_ < 0) return makeError("filter '" + context.name() + "': count must be >= 0");
    return {};
  }
  void process(FilterContext& context) override {
    if (emitInitialMessages(context, pending_, emitted_) && pending_ == 0) forwardAll(context);
  }
  bool exhausted(FilterContext& context) const override {
    return pending_ == 0 && Filter::exhausted(context);
  }

 private:
  long pending_ = 0;
  long emitted_ = 0;
};

FilterType initialType() {
  FilterType type = filterType("initial",
                               "Emits `count` empty messages on out at start-up, then forwards in "
                               "to out; starts a cycle of the network.",
                               inToOut);
  const app::ParamSpec count = intParam("count", "1", 0, static_cast<double>(kMaxInitialMessages),
                                        "messages emitted at start-up");
  type.params.push_back(count);
  type.initialMessages = [count](const std::vector<Param>& params) {
    return static_cast<int>(clampedInt(count, params));
  };
  return type;
}

}  // namespace

void registerForward(FilterRegistry& registry) {
  addBuiltin(registry, {filterType("passthrough",
                                   "Forwards every message from in to out unchanged.", inToOut),
                        factoryOf<PassthroughFilter>()});
  addBuiltin(registry,
             {filterType("broadcast",
                         "Forwards every message from in to each connection of out; chain them "
                         "as a tree to reach N receivers in O(log N) steps.",
                         inToOut),
              factoryOf<PassthroughFilter>()});
  addBuiltin(registry, {initialType(), factoryOf<InitialFilter>()});
}

}  // namespace vrflow::daemon::filters
