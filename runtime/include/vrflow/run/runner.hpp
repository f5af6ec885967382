#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/run/progress.hpp"

namespace vrflow::daemon {
struct DaemonOptions;
}

namespace vrflow::run {

/// Exit codes of `vrflow run`, stable for scripts and CI.
enum ExitCode : int {
  kExitOk = 0,
  kExitRunFailed = 1,     ///< a module died, a deadlock, a runtime error
  kExitInvalid = 2,       ///< bad command line or application file
  kExitTimeout = 3,       ///< --timeout exceeded
  kExitInterrupted = 130  ///< Ctrl-C or SIGTERM
};

class HostLink;
class EventStream;

/// How to run an application on this machine.
struct RunOptions {
  uint64_t iterations = 0;  ///< outer iterations; 0 = until the modules end or Ctrl-C
  /// Iterations of each module (by id) for `iterations` outer ones: a module behind a `repeat`
  /// of count k runs k times as many (app::iterationRates). Empty: computed from the
  /// application given to runApplication(), which must then be the whole one.
  std::map<std::string, uint64_t, std::less<>> moduleIterations;
  double timeoutSeconds = 0;    ///< 0 = no limit
  double deadlockSeconds = 10;  ///< no progress this long with every module waiting
  std::size_t segmentBytes = std::size_t{1} << 30;
  /// Caps each module process's data memory (RLIMIT_DATA); 0 = no cap. A module that runs out
  /// under it is reported with the cap as the cause.
  uint64_t moduleMemoryBytes = 0;
  std::string reportPath;                     ///< JSON report; empty = none
  ProgressMode progress = ProgressMode::Off;  ///< what stderr shows of the run (progress.hpp)
  double stopGraceSeconds = 2;                ///< after a stop request, before SIGTERM then SIGKILL
  double joinSeconds = 20;                    ///< a module must call Module::init() within this
  double lingerSeconds = 5;                   ///< a module that finished must exit within this
  HostLink* hostLink = nullptr;               ///< set by vrflow-daemon under the launcher
  /// The whole application when runApplication() gets one host's share (vrflow-daemon), to
  /// name the feeders on other hosts in deadlock reports; null: the application given.
  const app::Application* wholeApplication = nullptr;
  bool trace = false;     ///< record modules' spans (also implied by tracePath)
  std::string tracePath;  ///< Chrome trace-event JSON; empty = none
  /// Where the run's events go (docs/events.md): started, stats each second, warnings,
  /// module exits, end; null: nowhere.
  EventStream* events = nullptr;
  /// This run's id (run::newRunId); empty: none (a test, or a daemon under the launcher).
  std::string runId;
  /// The folder of the modules' logs (<module>.log each); empty: none.
  std::string logDir;
};

/// What happened, for the report and the exit code.
struct RunOutcome {
  RunOutcome() = default;
  RunOutcome(int code, std::string word, std::string message, std::string more = {})
      : exitCode(code),
        status(std::move(word)),
        error(std::move(message)),
        detail(std::move(more)) {}

  int exitCode = kExitOk;
  std::string status = "ok";  ///< ok, failed, deadlock, stalled, timeout, interrupted
  std::string error;          ///< one line a person can act on; empty on success
  /// For the terminal only, never the report: the failed module's log file and last lines.
  std::string detail;
};

/// What a daemon started by `vrflow launch` adds to a run: links to the other hosts' daemons
/// and the launcher's control channel (tools/daemon_main.cpp implements it).
class HostLink {
 public:
  virtual ~HostLink() = default;
  /// Adds the host id, the transport and the connections crossing hosts before the daemon is built.
  virtual void configure(daemon::DaemonOptions& options) = 0;
  /// Once the daemon is built, before modules start: links to peers, waits for the launcher.
  virtual Status ready() = 0;
  /// Every supervisor tick: an outcome ends the run (a peer lost, a stop from the launcher).
  virtual std::optional<RunOutcome> poll() = 0;
  /// After this host's modules ended: keeps routing until every host is done and every
  /// connection crossing hosts is over. Returns warnings for the report.
  virtual std::vector<std::string> drain(const RunOutcome& outcome) = 0;
  /// This host's run failed (a stall, a failed module, a time-out), said before its modules
  /// are stopped: stopping them takes a while (seconds under a sanitizer), and what their end
  /// does to the other hosts (a closed connection, a module ending) must not be reported there
  /// before the cause. drain() then does not repeat it. Ignored by default.
  virtual void failing(const RunOutcome& outcome) { (void)outcome; }
  /// This host's share of the run report (JSON text).
  virtual void report(const std::string& json) = 0;
  /// This host's trace events (run::hostTraceToJson), when the run is traced.
  virtual void trace(const std::string& json) = 0;
  /// About once a second: live counters of this host's modules and connections (JSON).
  virtual void stats(const std::string& json) = 0;
  /// A line that module `module` of this host printed, from the thread that reads the modules'
  /// output (docs/logs.md): the launcher prints and keeps it. Ignored by default.
  virtual void output(const std::string& module, std::string_view text) {
    (void)module;
    (void)text;
  }
};

/// How many iterations each module of the whole `application` runs in `outer` outer
/// iterations (RunOptions::moduleIterations).
std::map<std::string, uint64_t, std::less<>> moduleIterations(const app::Application& application,
                                                              uint64_t outer);

/// Runs `application` with every host mapped to this machine (the embedded default): one
/// daemon in this process, each module in its own process. Returns when every process of the
/// run has ended; nothing is left behind.
RunOutcome runApplication(const app::Application& application, const app::Catalog& catalog,
                          const RunOptions& options);

}  // namespace vrflow::run
