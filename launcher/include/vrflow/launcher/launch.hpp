#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <map>
#include <string>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/run/runner.hpp"

namespace vrflow::launcher {

/// One line of a hostfile: where a host of the application really runs.
struct HostEntry {
  std::string host;     ///< host id, as in the application file
  std::string address;  ///< overrides the file's address (where the daemon binds)
  /// mpirun, slurm: the machine the daemon runs on (an Open MPI hostfile's line, or `node=`).
  std::string node;
  std::string user;                     ///< ssh only
  int sshPort = 22;                     ///< ssh only
  std::string identity;                 ///< ssh only: private key file (ssh -i)
  std::vector<std::string> sshOptions;  ///< ssh only: -o KEY=VALUE
  std::string directory;  ///< ssh only: working folder there (default: the launcher's)
  std::string daemon;     ///< ssh only: vrflow-daemon there (default: the one beside `vrflow`)
  std::vector<std::string> environment;  ///< NAME=VALUE given to the daemon and its modules
  int line = 0;
};

/// Reads a hostfile, `#` comments and blank lines skipped. vrflow's format: `HOST [address=A]
/// [node=N] [user=U] [ssh-port=P] [identity=FILE] [ssh-option=K=V]... [dir=PATH] [daemon=PATH]
/// [env=NAME=VALUE]...` per line. Open MPI's, recognised by `slots=` or `max_slots=` on a line:
/// `MACHINE [slots=N] [max_slots=M]` per line, the application's hosts placed on the slots in
/// order (one entry per host, with `node`). Errors (a mixed or malformed line) name FILE:LINE.
Result<std::vector<HostEntry>> readHostfile(const std::string& path,
                                            const app::Application& application);

/// Settings of `vrflow launch`.
struct LaunchOptions {
  std::string appFile;
  std::string hostfile;
  std::string backend = "local";        ///< local, ssh, mpirun or slurm
  std::vector<std::string> mpirunArgs;  ///< `--mpirun-arg`: passed to mpirun before the ranks
  uint64_t iterations = 0;
  std::string reportPath;
  std::string tracePath;                     ///< Chrome trace of every host; empty = none
  std::string controlAddress = "127.0.0.1";  ///< mpirun: where daemons reach the launcher
  double timeoutSeconds = 0;
  double peerTimeoutSeconds = 3;   ///< heartbeat timeout between daemons
  double startSeconds = 30;        ///< every daemon must be linked within this
  uint64_t moduleMemoryBytes = 0;  ///< run::RunOptions::moduleMemoryBytes of every host
  std::vector<std::string> packageDirs, compositeDirs;
  std::vector<std::string> overrides;  ///< `--set ID.PARAM=VALUE`, applied by every daemon
  run::ProgressMode progress = run::ProgressMode::Off;  ///< what stderr shows of the launch
  /// The launch's event stream, merged from every host's (docs/events.md); null: none.
  run::EventStream* events = nullptr;
  /// This launch's id (run::newRunId); empty: none.
  std::string runId;
  /// The folder on the launcher's machine where every host's module logs are gathered
  /// (<module>.log each); empty: none.
  std::string logDir;
  /// `--log-level` of every daemon (run::parseLogLevel's words).
  std::string logLevel = "info";
};

/// Merges the hosts' report shares into one report in the shape `vrflow run` writes (modules,
/// connections and outputs in file order).
std::string mergeReports(const app::Application& application, const std::vector<std::string>& parts,
                         const run::RunOutcome& outcome, uint64_t iterations, double wallSeconds);

/// `vrflow monitor [RUN]`: shows the live state of a registered run or launch (run::findRun:
/// any unique start of its id; empty: the only running run), per host and module
/// (iterations/s, wait vs compute, state, CPU, memory), per connection (queue, messages/s,
/// bytes/s) and per link, each second until it ends. Returns 0, or 1 when there is no such run.
int monitor(const std::string& run, bool once, bool json);

/// `vrflow monitor [RUN] --follow-events`: the registered run's events as JSON lines
/// (docs/events.md) as they come, for a program that did not start it (the editor's "Attach"):
/// a `started` from its registration, each host's new `stats`, new warnings, and its `end`;
/// then returns 0. 1 when there is no such run or it has ended.
int followEvents(const std::string& run);

/// `vrflow monitor --events FILE|-`: the same table from an event stream (docs/events.md),
/// redrawn at each statistics event, until its "end" (a file still being written is followed;
/// `-` reads standard input to its end). `once`: the state at the end of what is there now.
int monitorEvents(const std::string& source, bool once, bool json);

/// Runs `application` (loaded, expanded and validated) with one daemon per host. Exit codes as
/// `vrflow run`.
run::RunOutcome launch(const app::Application& application, const LaunchOptions& options);

}  // namespace vrflow::launcher
