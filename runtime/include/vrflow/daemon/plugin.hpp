#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/daemon/filter_spec.hpp"

// Filter plugins: shared libraries that add filter types without rebuilding the runtime
// (docs/filters.md, "Plugins"). A plugin exports one function, whose name carries the ABI
// version it was built for, and fills in one FilterSpec per filter type it defines:
//
//   VRFLOW_FILTER_PLUGIN(specs) {  // exports vrflowFilterPluginV<ABI>
//     specs.push_back({declaration(), factory});
//   }
//
// The function passes the SDK's own C++ types: the plugin and the program that loads it use
// one copy of the filter SDK in the process, so both sides agree on them as long as they were
// built for the same ABI. A loaded plugin is never unloaded.

/// The filter plugin ABI: the version of what a plugin sees of vrflow (Filter, FilterContext,
/// FilterSpec, app::FilterType and the types they use). Bumped on any change to them; the name
/// of the entry point carries it, so that a plugin built for another version is refused.
#define VRFLOW_FILTER_PLUGIN_ABI 2

#define VRFLOW_DETAIL_PLUGIN_CAT(a, b) a##b
#define VRFLOW_DETAIL_PLUGIN_ENTRY(abi) VRFLOW_DETAIL_PLUGIN_CAT(vrflowFilterPluginV, abi)
#define VRFLOW_DETAIL_PLUGIN_TEXT(x) #x
#define VRFLOW_DETAIL_PLUGIN_STRING(x) VRFLOW_DETAIL_PLUGIN_TEXT(x)

/// The name of the entry point a plugin exports for this ABI (vrflowFilterPluginV2).
#define VRFLOW_FILTER_PLUGIN_ENTRY VRFLOW_DETAIL_PLUGIN_ENTRY(VRFLOW_FILTER_PLUGIN_ABI)

namespace vrflow::daemon {

/// VRFLOW_FILTER_PLUGIN_ABI as a number.
inline constexpr std::uint32_t kFilterPluginAbi = VRFLOW_FILTER_PLUGIN_ABI;
/// The prefix of every ABI's entry point; the version follows it.
inline constexpr const char* kFilterPluginEntryPrefix = "vrflowFilterPluginV";
/// The symbol a plugin for this ABI exports.
inline constexpr const char* kFilterPluginEntry =
    VRFLOW_DETAIL_PLUGIN_STRING(VRFLOW_FILTER_PLUGIN_ENTRY);

/// The function a plugin exports: appends one spec per filter type it defines.
using FilterPluginEntry = void (*)(std::vector<FilterSpec>& specs);

/// Environment variable listing plugins to load at start-up.
inline constexpr const char* kFilterPathVariable = "VRFLOW_FILTER_PATH";

/// Loads one plugin (once per process: its specs join FilterRegistry::instance()) and adds its
/// filter types to `catalog`. Refused, with a message naming the file: a file that cannot be
/// loaded (missing, unresolved symbol), one without an entry point, one built for another ABI
/// (the message names both versions), one defining no filter type, a type twice, or a type that
/// exists already (built in or from another plugin).
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

/// Put once in a plugin's source, at global scope, followed by the body of the entry point:
/// `specs` names its parameter, a std::vector<vrflow::daemon::FilterSpec>& to append to.
#define VRFLOW_FILTER_PLUGIN(specs)                                                  \
  extern "C" __attribute__((visibility("default"))) void VRFLOW_FILTER_PLUGIN_ENTRY( \
      std::vector<::vrflow::daemon::FilterSpec>& specs)
