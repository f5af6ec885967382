// A filter plugin that defines `merge`, a built-in type: the loader must refuse it and keep the
// built-in.
#include "vrflow/daemon/plugin.hpp"

namespace {

class NothingFilter final : public vrflow::daemon::Filter {
 public:
  void process(vrflow::daemon::FilterContext& /*context*/) override {}
};

}  // namespace

VRFLOW_FILTER_PLUGIN(specs) {
  vrflow::daemon::FilterSpec spec;
  spec.declaration.name = "merge";
  spec.factory = [](const vrflow::daemon::FilterContext&)
      -> vrflow::Result<std::unique_ptr<vrflow::daemon::Filter>> {
    return std::unique_ptr<vrflow::daemon::Filter>(std::make_unique<NothingFilter>());
  };
  specs.push_back(std::move(spec));
}
