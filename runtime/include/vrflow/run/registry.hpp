#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <sys/types.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/run/events.hpp"
#include "vrflow/run/run_state.hpp"

// The registry of runs (docs/operations.md): every `vrflow run` and `vrflow launch` registers
// as runtimeDirectory()/runs/<run id>/ (run.json: who it is; state.json: its live state, fed
// from its event stream) and, once ended, moves to stateDirectory()/runs/<run id>/, where the
// last kMaxEndedRuns are kept. `vrflow list`, `stop`, `monitor` and `logs` read it.
namespace vrflow::run {

/// Ended runs kept in the state folder (the oldest are removed beyond this).
constexpr std::size_t kMaxEndedRuns = 50;

/// Who a run is: written once, when it registers.
struct RunIdentity {
  std::string id;
  std::string kind = "run";  ///< "run" or "launch"
  std::string application, file;
  std::vector<std::string> hosts;    ///< host ids
  std::vector<std::string> modules;  ///< module ids
  pid_t pid = 0;                     ///< the `vrflow` process
  /// The process's start time (/proc/PID/stat, clock ticks since boot): a pid reused by
  /// another process is never mistaken for the run.
  uint64_t pidStart = 0;
  int64_t startTime = 0;    ///< seconds since the epoch
  uint64_t iterations = 0;  ///< -n; 0: none
  std::string logDir;       ///< empty: none
};

/// The identity of a run of `application` by this process.
RunIdentity identityOf(const app::Application& application, const std::string& kind,
                       const std::string& runId, uint64_t iterations, const std::string& logDir);

/// Whether the process `pid` that started at `pidStart` still runs.
bool processRuns(pid_t pid, uint64_t pidStart);

/// This process's registration: created when its run starts, fed the run's event lines,
/// moved to the state folder when destroyed (the run has ended).
class RunRegistration {
 public:
  /// Registers the run; an error if the runtime folder may not be trusted or written.
  static Result<std::unique_ptr<RunRegistration>> create(const RunIdentity& identity);
  ~RunRegistration();
  RunRegistration(const RunRegistration&) = delete;
  RunRegistration& operator=(const RunRegistration&) = delete;

  /// Takes one line of the run's event stream (not thread-safe: EventStream serialises).
  void event(const std::string& line);

 private:
  RunRegistration(RunIdentity identity, std::string folder);
  void save();

  RunIdentity identity_;
  std::string folder_;
  RunState state_;
};

/// What `vrflow run` and `vrflow launch` hold while they run: their registration and the event
/// stream that feeds it (the run's own `--events` stream, tee'd, or one of its own).
class RegisteredRun {
 public:
  /// Registers `identity`, fed by `given` (null: a stream of its own). A registry that cannot
  /// be used is a warning on stderr (the run goes on, unseen by `vrflow list`).
  RegisteredRun(const RunIdentity& identity, EventStream* given);
  ~RegisteredRun();
  RegisteredRun(const RegisteredRun&) = delete;
  RegisteredRun& operator=(const RegisteredRun&) = delete;
  /// The stream the run writes its events to: `given`, or its own (null without registration).
  EventStream* events() const { return events_; }

 private:
  std::unique_ptr<RunRegistration> registration_;
  std::unique_ptr<EventStream> own_;
  EventStream* events_ = nullptr;
};

/// A registered run as `vrflow list` shows it.
struct RunRecord {
  RunIdentity identity;
  RunState state;
  std::string folder;  ///< its folder in the registry
  bool running = false;
  /// "running", or the end's status (ok, failed, interrupted, ..., lost: killed without ending).
  std::string stateWord() const;
};

/// The running runs of this user, oldest first; with `all`, the ended ones too (from the state
/// folder). Runs found dead without an end are marked lost and moved to the state folder.
Result<std::vector<RunRecord>> listRuns(bool all);

/// The run whose id starts with `prefix` among listRuns(all); an empty prefix takes the only
/// running run. An error (naming the candidates) when there is none or more than one.
Result<RunRecord> findRun(const std::string& prefix, bool all);

/// The folder of the running runs: runtimeDirectory()/runs (created, checked).
Result<std::string> registryDirectory();

}  // namespace vrflow::run
