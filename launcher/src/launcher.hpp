#pragma once

// The launcher's inside, shared by its files: launch.cpp (the run, from start to the report),
// start_daemons.cpp (starting one daemon per host: local, ssh, mpirun), slurm.cpp (the slurm
// backend: the allocation's nodes, srun) and daemon_channel.cpp (reading what the daemons say).
// Nothing outside launcher/src includes it.
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/launcher/launch.hpp"
#include "vrflow/net/control.hpp"
#include "vrflow/net/transport.hpp"
#include "vrflow/run/module_logs.hpp"
#include "vrflow/run/progress.hpp"
#include "vrflow/run/runner.hpp"

namespace vrflow::launcher::detail {

using Clock = std::chrono::steady_clock;

/// This process's steady clock in nanoseconds (the daemons' clocks are aligned with it).
int64_t steadyNs();

/// Seconds from `t` to now.
double secondsSince(Clock::time_point t);

// One host's daemon, as the launcher sees it.
struct HostDaemon {
  int index = 0;
  std::string host, bind;
  pid_t pid = -1;
  int toDaemon = -1, fromDaemon = -1;
  std::string buffer;
  int port = -1;
  bool viaSsh = false;
  bool viaMpirun = false;
  bool viaSrun = false;
  bool connected = false, finished = false, exited = false;
  bool stopAnswered = false;  ///< it answered "stop"
  int finishedCode = 0;
  std::string finishedStatus, finishedError, report, exitText, trace;
  std::string stats;  ///< its last "stats" line (the progress line)
  bool clockKnown = false;
  int64_t clockOffsetNs = 0;  ///< the daemon's steady clock minus ours

  void send(const net::ControlCommand& command) const {
    if (toDaemon < 0) return;
    const std::string text = net::toLine(command) + "\n";
    [[maybe_unused]] auto n = write(toDaemon, text.data(), text.size());
  }
  std::string name() const {
    return "daemon of host '" + host + "' (" + bind +
           (viaSsh      ? ", ssh pid "
            : viaMpirun ? ", mpirun pid "
            : viaSrun   ? ", srun pid "
                        : ", pid ") +
           std::to_string(pid) + ")";
  }
};

/// Where one host's daemon runs, as a backend decided it.
struct Placement {
  std::string node;  ///< mpirun, slurm: the machine (empty: this one, or the file's address)
  std::string bind;  ///< the IPv4 address the daemon listens on, told to its peers
  std::vector<std::string> environment;  ///< NAME=VALUE from the hostfile
  const HostEntry* entry = nullptr;      ///< the host's hostfile line, if any
};

/// The IPv4 address of a machine name (getaddrinfo), or an error naming it.
Result<std::string> ipv4Of(const std::string& name);

/// The allocation a slurm launch runs in (SLURM_JOB_ID, SLURM_JOB_NODELIST): its nodes in
/// order (`scontrol show hostnames`) and their addresses (NodeAddr, `scontrol show node`).
struct SlurmAllocation {
  std::string jobId;
  std::vector<std::string> nodes;
  std::vector<std::string> addresses;  ///< IPv4, one per node
};

/// An error unless this process runs inside a Slurm allocation (SLURM_JOB_ID and
/// SLURM_JOB_NODELIST set).
Status insideSlurmAllocation();

/// The allocation this process runs in, or an error saying it runs in none.
Result<SlurmAllocation> slurmAllocation();

/// The checks of the command line and hostfile before anything starts (exit 2 when they fail):
/// the backend's needs (ssh: a hostfile; slurm: an allocation), machines only where honoured.
Status checkLaunch(const app::Application& application, const LaunchOptions& options);

/// One launch: starts a daemon per host, relays the control channel, stops them all.
class Launcher {
 public:
  Launcher(const app::Application& application, const LaunchOptions& options)
      : application_(application),
        options_(options),
        logs_({.logDir = options.logDir,
               .echo = true,
               .colour = run::ModuleLogs::colourOnTerminal(),
               .forward = {}}) {}
  run::RunOutcome run();

 private:
  Status start();
  Status startMpirun(const std::string& daemonPath, const net::Secret& secret,
                     const std::vector<HostEntry>& entries);
  // slurm: where host `index` runs, on the allocation's nodes in order or by the hostfile.
  Result<Placement> slurmPlacement(const SlurmAllocation& allocation, std::size_t index,
                                   const HostEntry* entry) const;
  // slurm: srun's words before the daemon's, for one host on `node`.
  std::vector<std::string> srunCommand(const std::string& node, const std::string& host) const;
  // slurm: cancels the job steps of this launch's daemons still there (a killed srun leaves them).
  void cancelSlurmSteps() const;
  // The options every daemon gets, whatever the backend: trace, peer timeout, iterations and
  // search paths (made absolute).
  void appendDaemonOptions(std::vector<std::string>& argv) const;
  void pump(int timeoutMs);
  void onLine(HostDaemon& d, const std::string& line);
  /// A module's line (or its dropped count) that `d` forwarded: printed and logged here.
  void onOutput(const HostDaemon& d, const net::ControlEvent& event);
  void failWith(run::RunOutcome outcome, bool rootCause);
  void stopAll();
  /// The progress line (run/progress.hpp) from the hosts' last statistics; with `end`, its
  /// summary.
  void showProgress(const run::RunOutcome* end = nullptr);
  bool allExited() const {
    for (const auto& d : daemons_) {
      if (!d.exited) return false;
    }
    return true;
  }

  const app::Application& application_;
  const LaunchOptions& options_;
  run::ModuleLogs logs_;      ///< every host's module lines, gathered on this machine
  bool logsRefused_ = false;  ///< a module's log file could not be made (said once)
  /// Where the launch's events go: options_.events, tee'd to the registry (run()).
  run::EventStream* events_ = nullptr;
  std::vector<HostDaemon> daemons_;
  int signalFd_ = -1;
  std::optional<run::RunOutcome> failure_;
  bool failureIsRoot_ = false;
  Clock::time_point failureAt_;
  bool interrupted_ = false;
  bool stopping_ = false;
  run::ProgressLine progress_{options_.progress, options_.iterations};
  /// Per module: its iterations for the launch's -n (run::moduleIterations); empty without -n.
  std::map<std::string, uint64_t, std::less<>> moduleTargets_;
};

}  // namespace vrflow::launcher::detail
