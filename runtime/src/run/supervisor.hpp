#pragma once

// The supervisor of a run's module processes, split by concept: supervisor.cpp (start, reap,
// stop: the run loop), stall_check.cpp (why nothing progresses: deadlock, stall, modules that
// never join or never leave), live_stats.cpp (progress line, statistics, traces). Private to
// runtime/src/run.
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "module_output.hpp"
#include "report.hpp"
#include "spawn.hpp"
#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/app/mpi_job.hpp"
#include "vrflow/daemon/daemon.hpp"
#include "vrflow/run/progress.hpp"
#include "vrflow/run/runner.hpp"
#include "vrflow/run/trace.hpp"

namespace vrflow::run::detail {

using Clock = std::chrono::steady_clock;

/// Seconds from `start` to now.
inline double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A module's state in words ("waiting", "blocked sending", ...), from its slot.
const char* stateName(ipc::ModuleState state);

/// What /proc/PID/stat says of a process: its state letter (R, S, D, T, t, Z...) and CPU time.
struct ProcessSample {
  char state = '?';
  uint64_t cpuNs = 0;
  bool known = false;
};

/// Reads /proc/PID/stat; `known` false when the process is gone.
ProcessSample sampleProcess(pid_t pid);

/// Starts, watches and stops the module processes of one host's share of a run.
class Supervisor {
 public:
  /// `jobs`: the MPI jobs of `application` (app::mpiJobs); those of several modules start as
  /// one mpirun each. `catalog`: the module types of `application`.
  Supervisor(const app::Application& application, const app::Catalog& catalog,
             const RunOptions& options, daemon::Daemon& daemon, std::vector<app::MpiJob> jobs);

  RunOutcome run();

 private:
  struct Child {
    pid_t pid = 0;
    int mpiRanks = 0;  ///< above 1: `pid` is the mpirun that runs this many ranks
    int job = -1;      ///< index in jobs_: `pid` is the mpirun of that job, shared by its modules
    bool alive = false;
    ModuleEnd end{"not started", "", std::nullopt, std::nullopt};
  };
  std::string jobLabel(const app::MpiJob& job, pid_t mpirun) const;
  std::optional<std::string> refusedWithoutMpirun() const;
  bool startJob(std::size_t jobIndex, ipc::JoinContract contract, RunOutcome& outcome);
  void reap(RunOutcome& outcome, bool stopping);
  void stopAll();
  std::size_t liveCount() const;
  pid_t processOf(std::size_t module) const;
  std::string memoryCause() const;
  std::string waitDetail(std::size_t module, bool& remote) const;
  std::optional<RunOutcome> noProgress();
  std::vector<uint64_t> stallCpuNs_;    ///< per module: CPU time when the stall check sampled
  Clock::time_point stallSampledAt_{};  ///< when; unset while modules progress
  bool notJoined(std::string& detail);
  bool lingering(std::string& detail);
  Clock::time_point finishedSince_{};
  /// The progress line (progress.hpp): redrawn about once a second; with `end`, its summary.
  void showProgress(const RunOutcome* end = nullptr);
  /// Once a second (or now, when `now`): the statistics to the launcher (hostLink) and the
  /// event stream.
  void publishStats(bool now = false);

 public:
  /// Moves what the modules traced into trace_ (no-op when the run is not traced).
  void drainTraces();
  HostTrace trace_;

  /// Live counters for `vrflow monitor`, the event stream and the progress line: raw totals,
  /// so that each reader computes rates.
  nlohmann::json statsSnapshot();
  Clock::time_point lastStats_{};

 private:
  const app::Application& application_;
  const app::Catalog& catalog_;
  const RunOptions& options_;
  daemon::Daemon& daemon_;
  std::vector<app::MpiJob> jobs_;  ///< only those of several modules
  std::vector<int> jobOf_;         ///< per module: its index in jobs_, or -1
  std::vector<Child> children_;
  MpiBackingFolder mpiFolder_;  ///< removed after every process of the run ended (~Supervisor)
  ModuleLogs logs_;             ///< where the modules' lines go (terminal, files, launcher)
  ModuleOutput output_{logs_};  ///< reads the modules' pipes into logs_
  std::vector<std::size_t> logIndex_;  ///< per module: its index in logs_
  long failed_ = -1;                   ///< the module whose end failed the run, if any
  /// A pipe for the process of `modules` (module indices), the write end or -1 with `outcome`.
  int outputPipe(const std::vector<std::size_t>& modules, bool mpiTagged, RunOutcome& outcome);
  /// The failed module's log file and last lines (RunOutcome::detail).
  std::string failureDetail() const;
  Clock::time_point start_ = Clock::now();
  uint64_t lastIterationSum_ = 0;
  Clock::time_point lastProgress_ = Clock::now();
  ProgressLine progress_{options_.progress, options_.iterations};

 public:
  std::vector<ModuleEnd> ends() const {
    std::vector<ModuleEnd> result;
    for (const auto& c : children_) result.push_back(c.end);
    return result;
  }
};

}  // namespace vrflow::run::detail
