// An example filter plugin: `every-nth` forwards one message in n (the 1st, the n+1-th, ...)
// and drops the others: a decimator. Built as a shared library, loaded by `vrflow` at run
// time; see README.md.
#include <algorithm>

#include "vrflow/daemon/plugin.hpp"

namespace {

using vrflow::daemon::Filter;
using vrflow::daemon::FilterContext;

class EveryNthFilter final : public Filter {
 public:
  explicit EveryNthFilter(long n) : n_(n) {}

  // Must not block: take what is buffered, emit what the output can take now.
  void process(FilterContext& context) override {
    auto& in = context.input(0);
    while (!in.empty()) {
      const bool keep = seen_ % n_ == 0;
      if (keep && !context.canEmit(0)) return;  // wait for room, keep the message
      if (keep) context.emit(0, std::move(in.front()));
      in.pop_front();
      ++seen_;
    }
  }

 private:
  long n_;
  long seen_ = 0;
};

// The filter type, declared once: what `vrflow validate` and the editor see, and the factory
// the daemon builds it with.
vrflow::daemon::FilterSpec everyNth() {
  using namespace vrflow::daemon;
  FilterSpec spec;
  spec.declaration.name = "every-nth";
  spec.declaration.doc =
      "Forwards the 1st, (n+1)-th, (2n+1)-th ... message of in to out; drops the others.";
  spec.declaration.params.push_back(intParam("n", "2", 1, 1000000, "keep one message in n"));
  spec.declaration.ports = [](const std::vector<vrflow::app::Param>&) {
    return std::vector<vrflow::app::PortSpec>{filterPort("in", true, "messages to decimate"),
                                              filterPort("out", false, "one message in n")};
  };
  spec.factory = [](const FilterContext& context) -> vrflow::Result<std::unique_ptr<Filter>> {
    // The catalog has checked n already; the factory still refuses what it cannot run.
    const long n = context.params().getInt("n");
    if (n < 1) return vrflow::makeError("filter '" + context.name() + "': n must be >= 1");
    return std::unique_ptr<Filter>(std::make_unique<EveryNthFilter>(n));
  };
  return spec;
}

}  // namespace

VRFLOW_FILTER_PLUGIN(specs) {
  specs.push_back(everyNth());
}
