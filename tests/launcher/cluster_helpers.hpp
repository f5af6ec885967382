#pragma once

// What the launcher tests share (hostfile, slurm, launch and ssh tests).

#include <sys/types.h>

#include <nlohmann/json.hpp>
#include <string>

namespace vrflow::testing {

/// A running vrflow-daemon as /proc shows it.
struct DaemonSeen {
  pid_t pid = -1;
  std::string commandLine;  ///< its words, each followed by a space
  std::string environment;  ///< "\nNAME=VALUE" each, then "\n"
};

/// The vrflow-daemon serving `host` of `appFile` (its command line names both), once it runs:
/// waits up to 30 s; pid -1 when none appeared. `program`: another process name (srun, ssh)
/// whose command line names both.
DaemonSeen findDaemon(const std::string& appFile, const std::string& host,
                      const std::string& program = "vrflow-daemon");

/// Whether a vrflow-daemon of `appFile` still runs.
bool daemonOfFileRuns(const std::string& appFile);

/// Points HOME, XDG_RUNTIME_DIR and XDG_STATE_HOME of this process (and so of what it starts,
/// Slurm jobs included) at folders (0700) of a temporary folder of its own, removed at exit.
void useOwnHome();

/// A report without its timings and without what names the file or the hosts.
nlohmann::json deterministicPart(const std::string& reportPath);

}  // namespace vrflow::testing
