// repeat and decimate: run a module k times faster than its neighbours (multi-rate).
// repeat: each message of `in` leaves k times, the time step divided by k and the simulation
// time advancing by that sub-step; decimate: only the last message of every k leaves.
#include <cstdint>

#include "filters.hpp"

namespace vrflow::daemon::filters {
namespace {

class RepeatFilter final : public Filter {
 public:
  explicit RepeatFilter(uint64_t count) : count_(count == 0 ? 1 : count) {}

  void process(FilterContext& context) override {
    auto& in = context.input(0);
    while (!in.empty() && context.canEmit(0)) {
      const auto view = viewOrWarn(context, in.front());
      if (!view) {
        in.pop_front();
        next_ = 0;
        continue;
      }
      const msg::StampsView stamps = view->stamps();
      const double subStep = stamps.timeStep / static_cast<double>(count_);
      auto copy = context.compose(view->bytes().size() + 64, [&](msg::MessageBuilder& builder) {
        builder.setStamps(stamps.toStamps());
        builder.setIteration(stamps.iteration * count_ + next_);
        builder.setSimTime(stamps.simTime + static_cast<double>(next_) * subStep);
        builder.setTimeStep(subStep);
        builder.setStampsOnly(view->stampsOnly());
        if (!view->stampsOnly()) builder.appendChunks(*view);
      });
      if (!copy) {
        context.warn("filter '" + context.name() + "': " + copy.error().message);
        return;  // shared memory is short: try again on the next pass
      }
      context.emit(0, std::move(*copy));
      if (++next_ == count_) {
        next_ = 0;
        in.pop_front();
      }
    }
  }

  // Ends once the last message has left all its copies.
  bool exhausted(FilterContext& context) const override {
    return context.inputClosed(0) && context.input(0).empty();
  }

 private:
  uint64_t count_;
  uint64_t next_ = 0;  // copies of in.front() already sent
};

class DecimateFilter final : public Filter {
 public:
  DecimateFilter(uint64_t count, bool restamp)
      : count_(count == 0 ? 1 : count), restamp_(restamp) {}

  void process(FilterContext& context) override {
    auto& in = context.input(0);
    while (!in.empty()) {
      if (seen_ + 1 < count_) {  // not the last of its group: only its time step counts
        if (const auto view = viewOrWarn(context, in.front())) {
          stepSum_ += view->stamps().timeStep;
        }
        in.pop_front();
        ++seen_;
        continue;
      }
      if (!context.canEmit(0)) return;
      MessageRef message = std::move(in.front());
      in.pop_front();
      const uint64_t group = groups_++;
      const double steps = stepSum_;
      seen_ = 0;
      stepSum_ = 0;
      if (!restamp_) {
        context.emit(0, std::move(message));
        continue;
      }
      const auto view = viewOrWarn(context, message);
      if (!view) continue;
      auto copy = context.compose(view->bytes().size() + 64, [&](msg::MessageBuilder& builder) {
        builder.setStamps(view->stamps().toStamps());
        builder.setIteration(group);
        builder.setTimeStep(steps + view->stamps().timeStep);
        builder.setStampsOnly(view->stampsOnly());
        if (!view->stampsOnly()) builder.appendChunks(*view);
      });
      if (!copy) {
        context.warn("filter '" + context.name() + "': " + copy.error().message);
        continue;
      }
      context.emit(0, std::move(*copy));
    }
  }

 private:
  uint64_t count_;
  bool restamp_;
  uint64_t seen_ = 0;    // messages of the current group consumed
  double stepSum_ = 0;   // their time steps
  uint64_t groups_ = 0;  // messages forwarded
};

}  // namespace

void registerMultiRate(FilterRegistry& registry) {
  registry.add("repeat", [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
    const long count = context.paramInt("count", 10);
    if (count < 1) return makeError("filter '" + context.name() + "': count must be >= 1");
    return std::unique_ptr<Filter>(std::make_unique<RepeatFilter>(static_cast<uint64_t>(count)));
  });
  registry.add("decimate", [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
    const long count = context.paramInt("count", 10);
    if (count < 1) return makeError("filter '" + context.name() + "': count must be >= 1");
    return std::unique_ptr<Filter>(std::make_unique<DecimateFilter>(
        static_cast<uint64_t>(count), context.paramBool("restamp", true)));
  });
}

}  // namespace vrflow::daemon::filters
