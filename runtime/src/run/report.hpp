#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "vrflow/daemon/daemon.hpp"
#include "vrflow/run/runner.hpp"

namespace vrflow::run {

/// What the supervisor knows of one module at the end.
struct ModuleEnd {
  std::string exit;   ///< "status 0", "signal 9", "running" (killed at stop)
  std::string cause;  ///< why it ended, when the runtime knows more than `exit` (empty if not)
  std::optional<int> exitCode;  ///< the status it exited with; none if killed or not reaped
  std::optional<int> signal;    ///< the signal that killed it; none if it exited
};

/// Records how a reaped module process ended (`waitStatus` as waitpid() gives it): the text
/// "status N" or "signal N" and the number.
void recordExit(ModuleEnd& end, int waitStatus);

/// Why a module ended, in words ("iteration count", "end of input", ...; ipc::EndCause).
std::string endCauseName(uint32_t cause);

/// The per-port counters of the application's filters and of the modules' default input
/// filters (the report's "filters" and the live statistics' "filters").
nlohmann::ordered_json filterStatsJson(const std::vector<daemon::FilterStats>& filters);

/// The modules that ended short of their iteration count (--iterations) because an input ended
/// (with no drop upstream to explain it) or because they left their loop, as one sentence
/// naming each with its count and cause; empty when there is none.
std::string shortModules(daemon::Daemon& daemon);

/// The run report as JSON text (what writeReport() writes).
std::string reportJson(const app::Application& application, daemon::Daemon& daemon,
                       const std::vector<ModuleEnd>& ends, const RunOutcome& outcome,
                       const RunOptions& options, double wallSeconds,
                       const std::vector<std::string>& warnings);

/// Writes the run report (JSON) described in the README. Deterministic fields first; timings
/// are grouped under "timing" objects so that two runs can be diffed without them.
Status writeReport(const std::string& path, const app::Application& application,
                   daemon::Daemon& daemon, const std::vector<ModuleEnd>& ends,
                   const RunOutcome& outcome, const RunOptions& options, double wallSeconds,
                   const std::vector<std::string>& warnings);

}  // namespace vrflow::run
