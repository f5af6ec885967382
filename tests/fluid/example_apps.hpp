#pragma once

#include <map>
#include <string>

#include "../runtime/process_helpers.hpp"

// Runs the examples' own application files through the real `vrflow run`, made fit for a test:
// the file is copied with its scene file named by absolute path, the viewer taken out (tests
// check the simulation; the scene tests check frames), and chosen parameters overridden.

namespace vrflow::testing {

/// Parameter values to set, keyed "module.param" (added when the module does not set it).
using ParamOverrides = std::map<std::string, std::string>;

/// The application examples/<folder>/<file> with the viewer module `camera` and its
/// connections removed, `scene.json` made absolute, and `overrides` applied.
std::string exampleForTest(const std::string& folder, const std::string& file,
                           const ParamOverrides& overrides, bool keepViewer = false);

/// Writes `app` into `dir` and runs it there for `iterations` (report in report.json), with
/// `extraArgs` (e.g. "--set water.blocks=4") on the command line; vrflow itself stops a run that
/// outlasts 80 % of the timeout (a hang fails cleanly).
CommandResult runApp(const TempDir& dir, const std::string& app, int iterations,
                     double timeoutSeconds = 240, const std::string& extraArgs = "");

}  // namespace vrflow::testing
