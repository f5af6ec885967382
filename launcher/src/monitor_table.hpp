#pragma once

#include <nlohmann/json.hpp>
#include <string>

// The table of `vrflow monitor` (monitor.cpp, monitor_events.cpp).
namespace vrflow::launcher {

/// The table `vrflow monitor` prints for one run: `launch` holds "application", "file",
/// "launcher_pid" or "pid" (optional) and "hosts", each with "host" and its last two statistics
/// snapshots "now" and "before" (null when not yet known): run::RunState's JSON.
std::string renderLaunch(const nlohmann::json& launch);

}  // namespace vrflow::launcher
