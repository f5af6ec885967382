// A filter plugin built for another filter plugin ABI (a later vrflow's, 999): its entry point
// is vrflowFilterPluginV999, not this vrflow's. The loader must refuse it with a message naming
// the file and both versions, and never call it.
#include <cstdlib>

#include "vrflow/daemon/plugin.hpp"

extern "C" __attribute__((visibility("default"))) void VRFLOW_DETAIL_PLUGIN_ENTRY(999)(
    std::vector<vrflow::daemon::FilterSpec>& /*specs*/) {
  std::abort();
}
