#pragma once

#include <nlohmann/json.hpp>
#include <string>

// The files of the monitor folder (monitorDirectory()): one "monitor-<launcher pid>.json" per
// running launch, read by `vrflow monitor`.
namespace vrflow::launcher {

/// Removes the monitor files (and temporaries) of launchers that no longer run (a launcher
/// killed with SIGKILL cannot remove its own).
void removeStaleMonitorFiles(const std::string& dir);

/// Replaces this launcher's monitor file in `dir` by `text`: written to a new temporary file
/// (O_EXCL, never through a link), then renamed over it. False if that failed.
bool publishMonitorFile(const std::string& dir, const std::string& text);

/// Removes this launcher's monitor file from `dir`.
void removeMonitorFile(const std::string& dir);

/// The table `vrflow monitor` prints for one launch: `launch` holds "application", "file",
/// "launcher_pid" (optional) and "hosts", each with "host" and its last two statistics
/// snapshots "now" and "before" (null when not yet known).
std::string renderLaunch(const nlohmann::json& launch);

}  // namespace vrflow::launcher
