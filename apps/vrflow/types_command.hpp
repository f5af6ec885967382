#pragma once

// `vrflow types [NAME] [--json]`: the module types of the node packages and the filter types
// (built in and from plugins) that an application may use, with their ports and parameters
// (docs/report.md, "vrflow types").

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace vrflow::apps {

/// What `vrflow types` shows.
struct TypesOptions {
  std::string name;   ///< PACKAGE, PACKAGE/TYPE or a filter type; empty: every type, one a line
  bool json = false;  ///< machine-readable, every detail
  std::vector<std::string> packageDirs;  ///< --packages, searched before the defaults
};

/// Adds the `types` subcommand to `cli`, filling `into` when it is parsed.
CLI::App* addTypesCommand(CLI::App& cli, TypesOptions& into);

/// Prints what `options` asks for on stdout. Returns 0, or 2 (run::kExitInvalid) for a name
/// that is neither a package, a module type nor a filter type (one message with a suggestion)
/// or a catalog that cannot be loaded.
int runTypes(const TypesOptions& options);

}  // namespace vrflow::apps
