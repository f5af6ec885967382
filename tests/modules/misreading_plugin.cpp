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

vrflow::app::FilterType declaration() {
  vrflow::app::FilterType type;
  type.name = "misread";
  type.doc = "Forwards in to out; its factory reads the undeclared parameter 'm'.";
  vrflow::app::ParamSpec n;
  n.name = "n";
  n.type = vrflow::app::ParamType::Int;
  n.defaultValue = "2";
  type.params.push_back(n);
  type.ports = [](const std::vector<vrflow::app::Param>&) {
    vrflow::app::PortSpec in;
    in.name = "in";
    in.required = true;
    vrflow::app::PortSpec out;
    out.name = "out";
    out.isInput = false;
    return std::vector<vrflow::app::PortSpec>{in, out};
  };
  return type;
}

}  // namespace

VRFLOW_FILTER_PLUGIN()

extern "C" void vrflowRegisterFilters(vrflow::daemon::FilterRegistry& registry,
                                      vrflow::app::Catalog& catalog) {
  registry.add("misread",
               [](const FilterContext& context) -> vrflow::Result<std::unique_ptr<Filter>> {
                 if (context.params().getInt("m") > 0) return vrflow::makeError("unreachable");
                 return std::unique_ptr<Filter>(std::make_unique<ForwardFilter>());
               });
  (void)catalog.addFilterType(declaration());
}
