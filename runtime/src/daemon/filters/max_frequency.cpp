// maxfrequency: at most F messages per second, on the daemon's timer.
#include <cmath>

#include "filters.hpp"

namespace vrflow::daemon::filters {
namespace {

class MaxFrequencyFilter final : public Filter {
 public:
  MaxFrequencyFilter(uint64_t periodNs, bool keepLatest)
      : periodNs_(periodNs), keepLatest_(keepLatest) {}

  void process(FilterContext& context) override {
    auto& in = context.input(0);
    if (keepLatest_) {
      while (in.size() > 1) {
        in.pop_front();
        context.countDropped(0, 1, "replaced by a newer message");
      }
    }
    if (in.empty()) return;
    const uint64_t now = context.nowNs();
    if (now < nextNs_) {
      context.wakeAfter(nextNs_ - now);
      return;
    }
    if (!context.canEmit(0)) return;
    context.emit(0, std::move(in.front()));
    in.pop_front();
    // From the actual send time, so that two messages are never closer than the period.
    nextNs_ = now + periodNs_;
    if (!in.empty()) context.wakeAfter(periodNs_);
  }

 private:
  uint64_t periodNs_;
  bool keepLatest_;
  uint64_t nextNs_ = 0;
};

app::FilterType maxFrequencyType() {
  FilterType type;
  type.name = "maxfrequency";
  type.doc =
      "Forwards in to out at most `frequency` times per second: two messages leave at least "
      "1/frequency s apart. `wait` holds early messages (the producer is paced); `latest` "
      "drops all but the newest pending one.";
  type.params.push_back(floatParam("frequency", "30", 0.001, 1e6, "most messages per second"));
  type.params.push_back(enumParam("mode", {"wait", "latest"}, "what happens to early messages"));
  type.ports = inToOut;
  return type;
}

}  // namespace

void registerMaxFrequency(FilterRegistry& registry) {
  addBuiltin(
      registry,
      {maxFrequencyType(), [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
         const double frequency = context.params().getFloat("frequency");
         if (!(frequency > 0.0) || !std::isfinite(frequency)) {
           return makeError("filter '" + context.name() + "': frequency must be a positive number");
         }
         const auto periodNs = static_cast<uint64_t>(std::llround(1e9 / frequency));
         return std::unique_ptr<Filter>(std::make_unique<MaxFrequencyFilter>(
             periodNs, context.params().getString("mode") == "latest"));
       }});
}

}  // namespace vrflow::daemon::filters
