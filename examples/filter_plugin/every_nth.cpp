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

vrflow::app::FilterType declaration() {
  vrflow::app::FilterType type;
  type.name = "every-nth";
  type.doc = "Forwards the 1st, (n+1)-th, (2n+1)-th ... message of in to out; drops the others.";
  vrflow::app::ParamSpec n;
  n.name = "n";
  n.type = vrflow::app::ParamType::Int;
  n.defaultValue = "2";
  n.min = 1;
  n.max = 1000000;
  n.doc = "keep one message in n";
  type.params.push_back(n);
  type.ports = [](const std::vector<vrflow::app::Param>&) {
    vrflow::app::PortSpec in;
    in.name = "in";
    in.required = true;
    in.doc = "messages to decimate";
    vrflow::app::PortSpec out;
    out.name = "out";
    out.isInput = false;
    out.doc = "one message in n";
    return std::vector<vrflow::app::PortSpec>{in, out};
  };
  return type;
}

}  // namespace

VRFLOW_FILTER_PLUGIN()

extern "C" void vrflowRegisterFilters(vrflow::daemon::FilterRegistry& registry,
                                      vrflow::app::Catalog& catalog) {
  registry.add("every-nth",
               [](const FilterContext& context) -> vrflow::Result<std::unique_ptr<Filter>> {
                 // The catalog has checked n already; the factory still refuses what it cannot run.
                 const long n = context.params().getInt("n");
                 if (n < 1)
                   return vrflow::makeError("filter '" + context.name() + "': n must be >= 1");
                 return std::unique_ptr<Filter>(std::make_unique<EveryNthFilter>(n));
               });
  (void)catalog.addFilterType(declaration());
}
