#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <string>
#include <string_view>

#include "vrflow/base/result.hpp"

// Where a run's files live: its id, the per-user runtime folder (live state, removed with the
// machine's session) and the per-user state folder (logs, kept after the run).
namespace vrflow::run {

/// A new run id, "<application>-<YYYYmmdd>-<HHMMSS>-<pid>" in local time: unique among the runs
/// of this machine and readable in `vrflow list`. Characters other than [A-Za-z0-9_.-] in the
/// application name become '_'.
std::string newRunId(std::string_view application);

/// The per-user runtime folder, mode 0700: $XDG_RUNTIME_DIR/vrflow, or /tmp/vrflow-<uid>;
/// created if missing. An error if it is not a folder of this user that only they may write
/// (as ssh and tmux refuse theirs).
Result<std::string> runtimeDirectory();

/// The per-user state folder (not created): $XDG_STATE_HOME/vrflow, or $HOME/.local/state/vrflow,
/// or /tmp/vrflow-state-<uid> without a home.
std::string stateDirectory();

/// Where a run's logs go without --log-dir: stateDirectory()/logs/<runId> (not created).
std::string defaultLogDirectory(const std::string& runId);

}  // namespace vrflow::run
