#pragma once

// The launcher's inside, shared by its files: launch.cpp (the run, from start to the report),
// start_daemons.cpp (starting one daemon per host: local, ssh, mpirun) and daemon_channel.cpp
// (reading what the daemons say). Nothing outside launcher/src includes it.
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/launcher/launch.hpp"
#include "vrflow/net/control.hpp"
#include "vrflow/net/transport.hpp"
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
  bool connected = false, finished = false, exited = false;
  bool stopAnswered = false;  ///< it answered "stop"
  int finishedCode = 0;
  std::string finishedStatus, finishedError, report, exitText, trace;
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
                        : ", pid ") +
           std::to_string(pid) + ")";
  }
};

/// One launch: starts a daemon per host, relays the control channel, stops them all.
class Launcher {
 public:
  Launcher(const app::Application& application, const LaunchOptions& options)
      : application_(application), options_(options) {}
  run::RunOutcome run();

 private:
  Status start();
  Status startMpirun(const std::string& daemonPath, const net::Secret& secret);
  // The options every daemon gets, whatever the backend: trace, peer timeout, iterations and
  // search paths (made absolute).
  void appendDaemonOptions(std::vector<std::string>& argv) const;
  void pump(int timeoutMs);
  void onLine(HostDaemon& d, const std::string& line);
  void failWith(run::RunOutcome outcome, bool rootCause);
  void stopAll();
  bool allExited() const {
    for (const auto& d : daemons_) {
      if (!d.exited) return false;
    }
    return true;
  }

  const app::Application& application_;
  const LaunchOptions& options_;
  /// Where the launch's events go: options_.events, tee'd to the registry (run()).
  run::EventStream* events_ = nullptr;
  std::vector<HostDaemon> daemons_;
  int signalFd_ = -1;
  std::optional<run::RunOutcome> failure_;
  bool failureIsRoot_ = false;
  Clock::time_point failureAt_;
  bool interrupted_ = false;
  bool stopping_ = false;
};

}  // namespace vrflow::launcher::detail
