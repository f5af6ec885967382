// stampfilter: forwards the message of `in` whose iteration an `order` message names.
#include <string>

#include "filters.hpp"

namespace vrflow::daemon::filters {
namespace {

constexpr std::size_t kIn = 0;
constexpr std::size_t kOrder = 1;

class StampFilter final : public Filter {
 public:
  explicit StampFilter(std::string stamp) : stamp_(std::move(stamp)) {}

  void process(FilterContext& context) override {
    auto& in = context.input(kIn);
    auto& orders = context.input(kOrder);
    while (!orders.empty()) {
      if (!target_) {
        target_ = targetOf(context, orders.front());
        if (!target_) {
          orders.pop_front();  // malformed (warned)
          continue;
        }
      }
      // Older messages can never be ordered any more (orders come in increasing order).
      uint64_t head = 0;
      while (!in.empty()) {
        const auto iteration = head_.of(context, in.front());
        if (iteration && *iteration >= *target_) {
          head = *iteration;
          break;
        }
        in.pop_front();
        context.countDropped(kIn, 1, "not ordered");
      }
      if (in.empty()) {
        if (!context.inputClosed(kIn)) return;  // wait for the ordered message
        skip(context);                          // it will never come
        orders.pop_front();
        continue;
      }
      if (head == *target_) {
        if (!context.canEmit(0)) return;
        context.emit(0, std::move(in.front()));
        in.pop_front();
      } else {
        skip(context);  // the ordered message was missed (it never came, or came too late)
      }
      orders.pop_front();
      target_.reset();
    }
  }

 private:
  std::optional<uint64_t> targetOf(FilterContext& context, const MessageRef& order) const {
    const auto view = viewOrWarn(context, order);
    if (!view) return std::nullopt;
    if (const auto stamp = view->stamps().user.find(stamp_)) {
      if (const auto value = stamp->asInt64(); value && *value >= 0) {
        return static_cast<uint64_t>(*value);
      }
    }
    return view->stamps().iteration;
  }

  void skip(FilterContext& context) {
    if (skipped_++ == 0) {
      context.warn("filter '" + context.name() + "': no message with iteration " +
                   std::to_string(*target_) + " for its order; skipped (reported once)");
    }
    target_.reset();
  }

  std::string stamp_;
  std::optional<uint64_t> target_;
  HeadIteration head_;
  uint64_t skipped_ = 0;
};

app::FilterType stampFilterType() {
  FilterType type;
  type.name = "stampfilter";
  type.doc =
      "For each message of order, forwards the message of in whose iteration stamp it names "
      "(its integer user stamp `stamp`, else its own iteration stamp); older messages of in "
      "are dropped, an order whose message is gone is skipped.";
  type.params.push_back(
      stringParam("stamp", "iteration", "the order's integer user stamp that names the iteration"));
  type.ports = [](const std::vector<Param>&) {
    return std::vector<PortSpec>{filterPort("in", true, "candidate messages, by iteration"),
                                 filterPort("order", true, "which iteration to forward next"),
                                 filterPort("out", false, "the ordered messages")};
  };
  return type;
}

}  // namespace

void registerStampFilter(FilterRegistry& registry) {
  addBuiltin(registry, {stampFilterType(),
                        [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
                          return std::unique_ptr<Filter>(
                              std::make_unique<StampFilter>(context.params().getString("stamp")));
                        }});
}

}  // namespace vrflow::daemon::filters
