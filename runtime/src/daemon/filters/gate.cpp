// gate: forwards `in` while open, drops it while closed; `open` sets the state.
#include "filters.hpp"

namespace vrflow::daemon::filters {
namespace {

constexpr std::size_t kIn = 0;
constexpr std::size_t kControl = 1;

class GateFilter final : public Filter {
 public:
  explicit GateFilter(bool open) : open_(open) {}

  void process(FilterContext& context) override {
    // Control messages first: the last one pending decides for the data pending now.
    auto& control = context.input(kControl);
    while (!control.empty()) {
      if (const auto view = viewOrWarn(context, control.front())) open_ = opens(*view);
      control.pop_front();
    }
    auto& in = context.input(kIn);
    while (!in.empty()) {
      if (open_) {
        if (!context.canEmit(0)) return;
        context.emit(0, std::move(in.front()));
      }
      if (!open_) context.countDropped(kIn, 1, "gate closed");
      in.pop_front();  // closed: dropped, so the producer is never held back
    }
  }

  // The control input may end first: the gate keeps its last state.
  bool exhausted(FilterContext& context) const override {
    return context.inputClosed(kIn) && context.input(kIn).empty();
  }

 private:
  // A user stamp `open` decides when present; otherwise a message with chunks opens.
  static bool opens(const msg::MessageView& message) {
    if (const auto stamp = message.stamps().user.find("open")) {
      if (const auto value = stamp->asInt64()) return *value != 0;
      if (const auto value = stamp->asDouble()) return *value != 0.0;
    }
    return message.chunkCount() > 0;
  }

  bool open_;
};

app::FilterType gateType() {
  FilterType type;
  type.name = "gate";
  type.doc =
      "Forwards in to out while open, drops in's messages while closed. Each message on open "
      "sets the state: an integer or float user stamp `open` opens when non-zero; without "
      "it, a message with at least one chunk opens and an empty one closes.";
  type.params.push_back(
      enumParam("initially", {"closed", "open"}, "the state before the first control message"));
  type.ports = [](const std::vector<Param>&) {
    return std::vector<PortSpec>{filterPort("in", true, "messages to forward or drop"),
                                 filterPort("open", true, "control messages: open or close"),
                                 filterPort("out", false, "the messages that found it open")};
  };
  return type;
}

}  // namespace

void registerGate(FilterRegistry& registry) {
  addBuiltin(registry,
             {gateType(), [](const FilterContext& context) -> Result<std::unique_ptr<Filter>> {
                return std::unique_ptr<Filter>(std::make_unique<GateFilter>(
                    context.params().getString("initially") == "open"));
              }});
}

}  // namespace vrflow::daemon::filters
