#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <string>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/model.hpp"

namespace vrflow::app {

/// What checkModuleFiles() looks at besides the file parameters.
struct ModuleFileChecks {
  /// Also check that each module type's executable written as a path exists and can be
  /// started (before a local run; not for `validate`, which may precede the build).
  bool executables = false;
};

/// Problems, on this machine, with the files an application's modules name: a file parameter
/// declared `access="input"` whose value is not a regular file (a missing file, a directory,
/// a FIFO, a device), one declared `access="output"` whose folder does not exist outside the
/// working folder (docs/application-format.md, "File parameters"); and, when asked, executables
/// that cannot be started, naming the manifest they were resolved from. A relative input is
/// looked up beside the application file first, then in the working folder, as the daemon does.
std::vector<Diagnostic> checkModuleFiles(const Application& app, const Catalog& catalog,
                                         const ModuleFileChecks& checks = {});

}  // namespace vrflow::app
