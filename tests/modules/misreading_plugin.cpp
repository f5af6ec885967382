// A filter plugin whose factory reads a parameter its declaration does not have: the daemon must
// refuse to start the run, naming the filter and the parameter.
#include "vrflow/daemon/plugin.hpp"

namespace {

using vrflow::daemon::Filter;
using vrflow::daemon::FilterContext;

class ForwardFilter final : public Filter {
 public:
  void process(FilterContext& context) override {
    auto& in = context.input(0);
    while (!in.empty() && context.canEmit(0)) {
      context.emit(0, std::move(in.front()));
      in.pop_front();
    }
  }
};

vrflow::daemon::FilterSpec misread() {
  using namespace vrflow::daemon;
  FilterSpec spec;
  spec.declaration.name = "misread";
  spec.declaration.doc = "Forwards in to out; its factory reads the undeclared parameter 'm'.";
  spec.declaration.params.push_back(intParam("n", "2", 0, 100, "declared, never read"));
  spec.declaration.ports = [](const std::vector<vrflow::app::Param>&) {
    return std::vector<vrflow::app::PortSpec>{filterPort("in", true, "messages"),
                                              filterPort("out", false, "the same messages")};
  };
  spec.factory = [](const FilterContext& context) -> vrflow::Result<std::unique_ptr<Filter>> {
    if (context.params().getInt("m") > 0) return vrflow::makeError("unreachable");
    return std::unique_ptr<Filter>(std::make_unique<ForwardFilter>());
  };
  return spec;
}

}  // namespace

VRFLOW_FILTER_PLUGIN(specs) {
  specs.push_back(misread());
}
