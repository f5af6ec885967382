#include "builtin_filters.hpp"

#include <vector>

#include "filters/filters.hpp"
#include "filters/merge.hpp"

namespace vrflow::daemon {
namespace {

// The default filter of a module's input port: initial messages first, then one message per
// incoming connection merged into one. `fifo` takes the oldest pending message of each
// connection (nothing is lost: a synchronous network keeps its data dependencies); `latest`
// keeps only the newest of each and never blocks the producers (greedy sampling); in a run that
// counts iterations, `latest` hands the last message again once every connection has ended,
// as long as the module runs, so that it reaches its count.
class PortInputFilter final : public Filter {
 public:
  Status start(FilterContext& context) override {
    initial_ = context.params().getInt("initial");
    latest_ = context.params().getString("mode") == "latest";
    if (latest_) merge_.keepLast();
    return {};
  }
  void process(FilterContext& context) override {
    if (!filters::emitInitialMessages(context, initial_, emittedInitial_) || initial_ > 0) return;
    if (!latest_) {
      merge_.process(context);
      return;
    }
    const std::size_t n = context.inputCount();
    if (newestIn_.size() != n) newestIn_.resize(n);
    bool anyPending = false;
    for (std::size_t i = 0; i < n; ++i) {
      auto& in = context.input(i);
      while (in.size() > 1) {
        in.pop_front();
        context.countDropped(i, 1, "replaced by a newer message");
      }
      if (!in.empty()) {
        newestIn_[i] = in.front();
        anyPending = true;
      }
    }
    // In a run that counts iterations, a connection whose producer has ended contributes its
    // newest message again, so the others' newer messages still reach the module.
    if (anyPending && context.runCountsIterations()) {
      for (std::size_t i = 0; i < n; ++i) {
        auto& in = context.input(i);
        if (in.empty() && context.inputClosed(i) && newestIn_[i].valid()) {
          in.push_back(newestIn_[i]);
        }
      }
    }
    merge_.process(context);
    if (const MessageRef* sent = merge_.lastEmitted()) last_ = *sent;
    // The ring holds at most one message: serve the last one again whenever the module took it.
    if (servesLastAfterEnd(context) && context.canEmit(0) && !context.outputEnded(0)) {
      context.emit(0, last_);
    }
  }
  bool exhausted(FilterContext& context) const override {
    if (initial_ != 0) return false;
    if (servesLastAfterEnd(context)) return context.outputEnded(0);
    return Filter::exhausted(context);
  }

 private:
  bool servesLastAfterEnd(FilterContext& context) const {
    return latest_ && last_.valid() && context.runCountsIterations() && Filter::exhausted(context);
  }
  long initial_ = 0;
  long emittedInitial_ = 0;
  bool latest_ = false;
  MessageRef last_;
  std::vector<MessageRef> newestIn_;  ///< latest mode: the newest message taken from each input
  filters::MergeFilter merge_;
};

// The daemon's per-port filters: built for the module ports it connects, never named by an
// application, so not in the catalog.
FilterSpec portFilterSpec(std::string name, FilterFactory factory) {
  FilterSpec spec;
  spec.declaration.name = std::move(name);
  spec.factory = std::move(factory);
  spec.inCatalog = false;
  return spec;
}

}  // namespace

void PortOutputFilter::process(FilterContext& context) {
  auto& in = context.input(0);
  while (!in.empty() && context.canEmit(0)) {
    last_ = in.front();
    ++forwarded_;
    context.emit(0, std::move(in.front()));
    in.pop_front();
  }
}

void registerBuiltinFilters(FilterRegistry& registry) {
  using filters::addBuiltin;
  using filters::factoryOf;
  filters::registerForward(registry);
  filters::registerMerge(registry);
  addBuiltin(registry, portFilterSpec("port-input", factoryOf<PortInputFilter>()));
  addBuiltin(registry, portFilterSpec("port-output", factoryOf<PortOutputFilter>()));
  filters::registerMultiplex(registry);
  filters::registerGate(registry);
  filters::registerRotate(registry);
  filters::registerScatter(registry);
  filters::registerLatest(registry);
  filters::registerMaxFrequency(registry);
  filters::registerStampFilter(registry);
  filters::registerTypeFilter(registry);
  filters::registerMultiRate(registry);
  filters::registerRoute(registry);
}

}  // namespace vrflow::daemon
