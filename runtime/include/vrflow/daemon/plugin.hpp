#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/daemon/filter.hpp"

// Filter plugins: shared libraries that add filter types without rebuilding the runtime
// (docs/filters.md, "Plugins"). A plugin exports two C functions:
//
//   VRFLOW_FILTER_PLUGIN()   // exports vrflowFilterPluginAbi()
//   extern "C" void vrflowRegisterFilters(vrflow::daemon::FilterRegistry& registry,
//                                         vrflow::app::Catalog& catalog) {
//     registry.add("every-nth", factory);       // what the daemon runs
//     (void)catalog.addFilterType(declaration);  // what `vrflow validate` and the editor see
//   }
//
// It links no vrflow library: its references to vrflow resolve against the program that loads
// it (`vrflow` and `vrflow-daemon` export the whole runtime), so there is one copy of every
// vrflow symbol in the process. A loaded plugin is never unloaded.

namespace vrflow::daemon {

/// Version of what a plugin sees of vrflow (Filter, FilterContext, FilterRegistry,
/// app::Catalog); a plugin built against another version is refused. Bumped on any change.
inline constexpr std::uint32_t kFilterPluginAbi = 1;

/// The function a plugin exports as `vrflowRegisterFilters`.
using RegisterFiltersFunction = void (*)(FilterRegistry& registry, app::Catalog& catalog);

/// Environment variable listing plugins to load at start-up.
inline constexpr const char* kFilterPathVariable = "VRFLOW_FILTER_PATH";

/// Loads one plugin (once per process; later calls only add its types to `catalog`). Refused,
/// with a message naming the file: a file that cannot be loaded (missing, unresolved symbol),
/// one without the two exported functions or built for another kFilterPluginAbi, one whose
/// registered factories and catalog declarations differ, or one defining a type that exists
/// already (built in or from another plugin).
Status loadFilterPlugin(const std::string& path, app::Catalog& catalog);

/// The plugin files `variable` lists: ':'-separated files or folders (a folder stands for its
/// `*.so` files, sorted); entries that do not exist are skipped.
std::vector<std::string> filterPluginsFromEnvironment(const char* variable = kFilterPathVariable);

/// Loads each file; every failure is reported, one per line.
Status loadFilterPlugins(const std::vector<std::string>& paths, app::Catalog& catalog);

/// Loads the plugins that the application's filters name in their `plugin` attribute. A
/// relative name is looked up next to the application file, then in the folders of
/// VRFLOW_FILTER_PATH, then in `<program>/../lib/vrflow/filters`. Each failure is an error at
/// the attribute.
std::vector<app::Diagnostic> loadApplicationPlugins(const app::Application& application,
                                                    app::Catalog& catalog);

}  // namespace vrflow::daemon

/// Put once in a plugin's source, at global scope: exports the plugin interface version it was
/// built with, which the loader checks.
#define VRFLOW_FILTER_PLUGIN()                                                              \
  extern "C" __attribute__((visibility("default"))) std::uint32_t vrflowFilterPluginAbi() { \
    return ::vrflow::daemon::kFilterPluginAbi;                                              \
  }
