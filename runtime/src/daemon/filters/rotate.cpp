// rotate: round-robin dispatch to N workers; unrotate: their results back in the original order.
#include <vector>

#include "filters.hpp"

namespace vrflow::daemon::filters {
namespace {

class RotateFilter final : public Filter {
 public:
  void process(FilterContext& context) override {
    auto& in = context.input(0);
    // Strict turns (never skipping a busy worker) keep the dispatch, and so the results,
    // the same on every run.
    while (!in.empty() && context.canEmit(next_)) {
      context.emit(next_, std::move(in.front()));
      in.pop_front();
      next_ = (next_ + 1) % context.outputCount();
    }
  }

 private:
  std::size_t next_ = 0;
};

class UnrotateFilter final : public Filter {
 public:
  UnrotateFilter(std::size_t inputs, bool byIteration)
      : byIteration_(byIteration), heads_(inputs) {}

  void process(FilterContext& context) override {
    while (context.canEmit(0)) {
      const auto input = byIteration_ ? smallestIteration(context) : nextInTurn(context);
      if (!input) return;
      auto& queue = context.input(*input);
      context.emit(0, std::move(queue.front()));
      queue.pop_front();
    }
  }

  bool exhausted(FilterContext& context) const override { return allInputsDone(context); }

 private:
  // The input whose turn it is, once it has a message; inputs that ended are skipped.
  std::optional<std::size_t> nextInTurn(FilterContext& context) {
    const std::size_t n = context.inputCount();
    for (std::size_t tried = 0; tried < n; ++tried) {
      const std::size_t i = turn_;
      if (!context.input(i).empty()) {
        turn_ = (turn_ + 1) % n;
        return i;
      }
      if (!context.inputClosed(i)) return std::nullopt;  // wait for this worker
      turn_ = (turn_ + 1) % n;
    }
    return std::nullopt;
  }

  // The input whose head has the smallest (iteration, input) once every input that may still
  // receive something has a head: each worker's results come in order, so this merges them.
  std::optional<std::size_t> smallestIteration(FilterContext& context) {
    std::optional<std::size_t> best;
    uint64_t bestIteration = 0;
    for (std::size_t i = 0; i < context.inputCount(); ++i) {
      auto& queue = context.input(i);
      while (!queue.empty()) {
        if (const auto iteration = heads_[i].of(context, queue.front())) {
          if (!best || *iteration < bestIteration) {
            best = i;
            bestIteration = *iteration;
          }
          break;
        }
        queue.pop_front();  // malformed: dropped (warned)
      }
      if (queue.empty() && !context.inputClosed(i)) return std::nullopt;
    }
    return best;
  }

  bool byIteration_;
  std::size_t turn_ = 0;
  std::vector<HeadIteration> heads_;
};

app::FilterType rotateType() {
  FilterType type;
  type.name = "rotate";
  type.doc =
      "Dispatches the messages of in round-robin to out0..out{N-1}: message k goes to "
      "out{k mod N} (waiting for that output when it is full), by reference.";
  const app::ParamSpec outputCount =
      intParam("outputs", "2", 1, kMaxPorts, "number of outputs N (workers)");
  type.params.push_back(outputCount);
  type.ports = [outputCount](const std::vector<Param>& params) {
    std::vector<PortSpec> ports{filterPort("in", true, "messages to dispatch")};
    for (auto& port : numberedPorts("out", clampedInt(outputCount, params), false,
                                    "every N-th message, to one worker")) {
      ports.push_back(std::move(port));
    }
    return ports;
  };
  return type;
}

app::FilterType unrotateType() {
  FilterType type;
  type.name = "unrotate";
  type.doc =
      "Puts the results of N workers fed by a rotate back in the original order on out. "
      "`iteration`: the pending message with the smallest iteration stamp goes first (ties: "
      "lower input first), once every open input has one; `round-robin`: in0, in1, ... in "
      "turn.";
  const app::ParamSpec inputCount =
      intParam("inputs", "2", 1, kMaxPorts, "number of inputs N (workers)");
  type.params.push_back(inputCount);
  type.params.push_back(
      enumParam("order", {"iteration", "round-robin"}, "how the original order is found back"));
  type.ports = [inputCount](const std::vector<Param>& params) {
    auto ports = numberedPorts("in", clampedInt(inputCount, params), true, "one worker's results");
    ports.push_back(filterPort("out", false, "every result, in the original order"));
    return ports;
  };
  return type;
}

}  // namespace

void registerRotate(FilterRegistry& registry) {
  addBuiltin(registry, {rotateType(), factoryOf<RotateFilter>()});
  addBuiltin(registry,
             {unrotateType(), [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
                return std::unique_ptr<Filter>(std::make_unique<UnrotateFilter>(
                    context.inputCount(), context.params().getString("order") != "round-robin"));
              }});
}

}  // namespace vrflow::daemon::filters
