#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <string>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"

// Parameters set on the command line (`--set ID.PARAM=VALUE`) over those of the file, so that one
// application file serves several runs (a CI matrix, a benchmark with more blocks).

namespace vrflow::app {

/// Sets, in order, each `ID.PARAM=VALUE` of `settings` on the module or filter ID of the
/// expanded application (ids as `vrflow expand` prints them; PARAM is what follows the last dot
/// of the part before '='), adding the parameter when the file does not set it. The value is
/// checked later by validation like one written in the file; diagnostics about it name
/// `--set ID.PARAM=VALUE` as their place. Errors: a setting without '=' or a dot, or an ID that
/// names no module or filter (nor an instance: applyInstanceOverrides takes those first).
Status applyOverrides(Application& application, const std::vector<std::string>& settings);

/// Before composite expansion: sets each `ID.PARAM=VALUE` of `settings` whose ID names an
/// instance of the application itself (not one inside a composite) on that instance, so that
/// `--set water.blocks=4` changes what a composite makes; such settings are removed from
/// `settings`, the others are left for applyOverrides on the expanded application. The value is
/// checked by the expansion like one written in the file (its place: `--set ...`).
void applyInstanceOverrides(Application& application, std::vector<std::string>& settings);

}  // namespace vrflow::app
