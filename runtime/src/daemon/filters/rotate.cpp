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

}  // namespace

void registerRotate(FilterRegistry& registry) {
  registry.add("rotate", factoryOf<RotateFilter>());
  registry.add("unrotate", [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
    return std::unique_ptr<Filter>(std::make_unique<UnrotateFilter>(
        context.inputCount(), context.params().getString("order") != "round-robin"));
  });
}

}  // namespace vrflow::daemon::filters
