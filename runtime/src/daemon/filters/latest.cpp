// latest: greedy sampling. Keeps the newest message of `in`; each `sync` message forwards it.
// In a run that counts iterations, the newest message is served again once `in` has ended, so
// that the consumer reaches its count.
#include "filters.hpp"

namespace vrflow::daemon::filters {
namespace {

constexpr std::size_t kIn = 0;
constexpr std::size_t kSync = 1;

class LatestFilter final : public Filter {
 public:
  explicit LatestFilter(bool repeat) : repeat_(repeat) {}

  Status start(FilterContext& context) override {
    const long initial = context.params().getInt("initial-sync");
    if (initial < 0) return makeError("filter '" + context.name() + "': initial-sync must be >= 0");
    triggers_ = static_cast<uint64_t>(initial);
    return {};
  }

  void process(FilterContext& context) override {
    auto& in = context.input(kIn);
    while (in.size() > 1) {  // only the newest matters: the producer never waits
      in.pop_front();
      context.countDropped(kIn, 1, "replaced by a newer message");
    }
    auto& sync = context.input(kSync);
    triggers_ += sync.size();
    sync.clear();
    const bool again = repeat_ || servesLastAfterEnd(context);
    while (triggers_ > 0 && context.canEmit(0)) {
      if (!in.empty()) {
        last_ = in.front();
        context.emit(0, std::move(in.front()));
        in.pop_front();
      } else if (again && last_.valid() && !context.outputEnded(0)) {
        context.emit(0, last_);
      } else {
        return;  // the trigger waits for the next message
      }
      --triggers_;
    }
  }

  // Ends with the data (no new message will come) or with the triggers; when it serves its
  // last message after the data, with the triggers or the consumer.
  bool exhausted(FilterContext& context) const override {
    const bool dataDone = context.inputClosed(kIn) && context.input(kIn).empty();
    const bool syncDone =
        context.inputClosed(kSync) && context.input(kSync).empty() && triggers_ == 0;
    if (dataDone && last_.valid() && servesLastAfterEnd(context)) {
      return syncDone || context.outputEnded(0);
    }
    return dataDone || syncDone;
  }

 private:
  static bool servesLastAfterEnd(FilterContext& context) {
    return context.runCountsIterations() && context.inputClosed(kIn) && context.input(kIn).empty();
  }

  bool repeat_;
  uint64_t triggers_ = 0;
  MessageRef last_;
};

app::FilterType latestType() {
  FilterType type;
  type.name = "latest";
  type.doc =
      "Greedy sampling: keeps only the newest message of in (older ones are dropped at once, "
      "so the producer never waits), and forwards it on out for each message of sync.";
  const app::ParamSpec initialSync =
      intParam("initial-sync", "1", 0, static_cast<double>(kMaxInitialMessages),
               "sync messages assumed received at start-up (starts the reader -> sync cycle)");
  type.params.push_back(initialSync);
  type.params.push_back(boolParam("repeat", "false",
                                  "answer a sync with the last forwarded message again when "
                                  "nothing newer came (else the sync waits for one)"));
  type.ports = [](const std::vector<Param>&) {
    return std::vector<PortSpec>{filterPort("in", true, "messages to sample"),
                                 filterPort("sync", true, "one message per wanted sample"),
                                 filterPort("out", false, "the newest message, once per sync")};
  };
  type.initialMessages = [initialSync](const std::vector<Param>& params) {
    return static_cast<int>(clampedInt(initialSync, params));
  };
  return type;
}

}  // namespace

void registerLatest(FilterRegistry& registry) {
  addBuiltin(registry,
             {latestType(), [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
                return std::unique_ptr<Filter>(
                    std::make_unique<LatestFilter>(context.params().getBool("repeat")));
              }});
}

}  // namespace vrflow::daemon::filters
