// multiplex: every message of any input, forwarded as it comes, renumbered.
#include "filters.hpp"

namespace vrflow::daemon::filters {
namespace {

class MultiplexFilter final : public Filter {
 public:
  explicit MultiplexFilter(bool renumber) : renumber_(renumber) {}

  void process(FilterContext& context) override {
    const std::size_t n = context.inputCount();
    // One message of each waiting input in turn, starting after the input served last, so
    // that a busy input never starves the others.
    for (std::size_t idle = 0; idle < n && context.canEmit(0);) {
      auto& in = context.input(next_);
      next_ = (next_ + 1) % n;
      if (in.empty()) {
        ++idle;
        continue;
      }
      idle = 0;
      MessageRef message = std::move(in.front());
      in.pop_front();
      forward(context, std::move(message));
    }
  }

  bool exhausted(FilterContext& context) const override { return allInputsDone(context); }

 private:
  void forward(FilterContext& context, MessageRef message) {
    if (!renumber_) {
      context.emit(0, std::move(message));
      ++sent_;
      return;
    }
    const auto view = viewOrWarn(context, message);
    if (!view) return;
    auto renumbered = restamp(context, *view, sent_);
    if (!renumbered) {
      context.warn(renumbered.error().message);
      return;
    }
    context.emit(0, std::move(*renumbered));
    ++sent_;
  }

  bool renumber_;
  std::size_t next_ = 0;
  uint64_t sent_ = 0;
};

app::FilterType multiplexType() {
  FilterType type;
  type.name = "multiplex";
  type.doc =
      "Forwards each message of in0..in{N-1} to out as it comes (one input after the other "
      "when several wait), renumbered: the iteration stamp counts the messages sent.";
  declareNumberedInputs(type, "messages to forward", "every message, in arrival order");
  type.params.push_back(
      boolParam("renumber", "true",
                "stamp each message's iteration with the count of messages sent (a "
                "copy); false forwards them untouched, by reference"));
  return type;
}

}  // namespace

void registerMultiplex(FilterRegistry& registry) {
  addBuiltin(registry,
             {multiplexType(), [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
                return std::unique_ptr<Filter>(
                    std::make_unique<MultiplexFilter>(context.params().getBool("renumber")));
              }});
}

}  // namespace vrflow::daemon::filters
