#pragma once

// What the editor shows about an application besides its elements: the problems of
// `vrflow validate` tied to the nodes and connections at fault, an automatic layout, and what a
// run reported.

#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/editor/edit.hpp"

namespace vrflow::editor {

/// One problem of the application, with what it points at.
struct Problem {
  app::Diagnostic::Severity severity = app::Diagnostic::Error;
  std::string text;  ///< as `vrflow validate` prints it (FILE:LINE:COL: error: ...)
  std::string message;
  std::string node;                       ///< module, filter or instance at fault, or empty
  std::optional<std::size_t> connection;  ///< index in Application::connections, or none
  std::vector<std::size_t> cycle;         ///< a deadlock: the connections of the cycle
};

/// Extra checks run on the loaded form (the window passes the filter plugin loader).
using ExtraCheck = std::function<std::vector<app::Diagnostic>(const app::Application&)>;

/// Every problem `vrflow validate` would print for `app` saved as it is now (same loader, same
/// rules: the application is saved to text and checked as the command checks a file), each
/// tied to its node or connection. When `opened` is given and `app` is still what was loaded
/// from it, its own text is checked, so that lines are those of the file on disk.
std::vector<Problem> findProblems(const app::Application& app, const app::Catalog& catalog,
                                  const ExtraCheck& extra = {}, const OpenedText* opened = nullptr);

/// Positions (x, y of the top-left corner, y down) for every node, from Graphviz `dot`, left to
/// right. `sizes` gives each node's width and height (missing: 160 x 80).
std::map<std::string, std::pair<double, double>> autoLayout(
    const app::Application& app,
    const std::map<std::string, std::pair<double, double>>& sizes = {});

/// What a run's --report holds that the editor draws.
struct RunReport {
  std::string status;  ///< "ok", "failed", ...
  std::string error;
  double wallSeconds = 0;
  struct ModuleStats {
    long long iterations = 0;
    std::string exit;
  };
  std::map<std::string, ModuleStats> modules;
  struct ConnectionStats {
    std::string from;
    std::string to;
    long long messages = 0;
    long long bytes = 0;
    long long dropped = 0;
  };
  std::vector<ConnectionStats> connections;
  /// The module named in `error` ("module 'x' ..."), or empty.
  std::string failedModule;
};

/// Parses the JSON of `vrflow run --report`.
Result<RunReport> parseRunReport(const std::string& json);

/// The module a run error names first ("module 'x' ..."), or empty.
std::string moduleNamedIn(const std::string& error);

}  // namespace vrflow::editor
