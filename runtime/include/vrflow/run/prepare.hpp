#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/app/package_files.hpp"
#include "vrflow/base/result.hpp"

// The one path from an application file to an application ready to run, shared by every
// program (`vrflow validate|expand|run|launch`, `vrflow-daemon`): load the file, expand its
// composites, apply the command line's --set, load its filter plugins, validate.
namespace vrflow::run {

/// The node packages on the search path: `extraDirs` first, then $VRFLOW_PACKAGE_PATH, then
/// <folder of this executable>/../share/vrflow/packages (the build tree and installs alike);
/// plus every filter type: daemon::makeCatalog()'s and the filter plugins' of
/// $VRFLOW_FILTER_PATH.
Result<app::Catalog> loadCatalog(const std::vector<std::string>& extraDirs);

/// What prepare() does, and with what.
struct PrepareSettings {
  std::string file;  ///< the application file
  /// The file's text when it is not read from disk (a model built in code, checked as if saved
  /// at `file`: relative paths are taken from its folder); nullopt: read `file`.
  std::optional<std::string> text = std::nullopt;
  /// --packages, searched before the file's <packages> folders and the defaults
  std::vector<std::string> packageDirs;
  std::vector<std::string> compositeDirs;  ///< --composites, searched after the file's folder
  std::vector<std::string> overrides;      ///< --set ID.PARAM=VALUE, in order
  /// Load the catalog and the application's plugins, and validate. Without: load, expand and
  /// apply --set only (`vrflow expand`).
  bool validate = true;
  /// Also check the files the modules name on this machine (validate only).
  std::optional<app::ModuleFileChecks> files;
  /// Names the program in the errors that do not name a file ("vrflow: ...").
  std::string program = "vrflow";
};

/// An application ready to run, or why not.
struct Prepared {
  std::optional<app::Application> application;  ///< the flat application; none on error
  std::optional<app::Catalog> catalog;          ///< loaded when validating and it could be
  std::vector<app::Diagnostic> diagnostics;     ///< every problem found, sorted, deduplicated
  /// An error that stopped the preparation before its diagnostics were complete (the catalog,
  /// a file that cannot be read, a bad --set), as one line to print; empty when none.
  std::string error;
  /// True when `error` is that the node packages could not be loaded.
  bool catalogFailed = false;
  /// True when the application is ready (no error, no diagnostic of severity error).
  bool ok() const { return application.has_value(); }
};

/// Load → expand composites → apply --set → load plugins → validate (docs/supervision.md,
/// "Preparing an application").
/// Never prints.
Prepared prepare(const PrepareSettings& settings);

/// Prints `prepared`'s error and its first `maxPrinted` diagnostics on stderr, one per line,
/// then how many more there are.
void printProblems(const Prepared& prepared, std::size_t maxPrinted = static_cast<std::size_t>(-1));

}  // namespace vrflow::run
