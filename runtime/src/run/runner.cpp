#include "vrflow/run/runner.hpp"

#include <signal.h>
#include <sys/ioctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "report.hpp"
#include "spawn.hpp"
#include "vrflow/app/graph.hpp"
#include "vrflow/app/mpi_job.hpp"
#include "vrflow/base/assert.hpp"
#include "vrflow/base/executable_dir.hpp"
#include "vrflow/daemon/daemon.hpp"
#include "vrflow/daemon/filter_registry.hpp"
#include "vrflow/daemon/plugin.hpp"
#include "vrflow/message/ids.hpp"
#include "vrflow/run/trace.hpp"

namespace vrflow::run {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

const char* stateName(uint32_t state) {
  switch (static_cast<ipc::ModuleState>(state)) {
    case ipc::ModuleState::Starting:
      return "starting";
    case ipc::ModuleState::Waiting:
      return "waiting";
    case ipc::ModuleState::Computing:
      return "computing";
    case ipc::ModuleState::Putting:
      return "blocked sending";
    case ipc::ModuleState::Finished:
      return "finished";
  }
  return "?";
}

// A port's name as the module's memory holds it (bounded: that memory is the module's to write).
std::string portName(const ipc::PortSlot& port) {
  return std::string(port.name, strnlen(port.name, sizeof port.name));
}

// Who feeds an input port, for deadlock reports: `whole` is the whole application, `local`
// this host's share of it (the same under `vrflow run`). Sets `remote` if a feeder is elsewhere.
std::string sourcesOf(const app::Application& whole, const app::Application& local,
                      const std::string& module, const std::string& port, bool& remote) {
  std::string text;
  for (const auto& c : whole.connections) {
    if (c.to.node != module || c.to.port != port) continue;
    text += (text.empty() ? "" : ", ") + app::toString(c.from);
    const bool here = std::any_of(local.modules.begin(), local.modules.end(),
                                  [&](const app::Module& m) { return m.id == c.from.node; }) ||
                      std::any_of(local.filters.begin(), local.filters.end(),
                                  [&](const app::Filter& f) { return f.id == c.from.node; });
    if (!here) {
      remote = true;
      std::string host = "?";
      for (const auto& m : whole.modules) {
        if (m.id == c.from.node) host = app::effectiveHost(whole, m.host);
      }
      for (const auto& f : whole.filters) {
        if (f.id == c.from.node) host = app::effectiveHost(whole, f.host);
      }
      text += " on host " + host;
    }
  }
  return text.empty() ? "initial messages only" : "from " + text;
}

// What /proc/PID/stat says of a process: its state letter (R, S, D, T, t, Z...) and CPU time.
struct ProcessSample {
  char state = '?';
  uint64_t cpuNs = 0;
  bool known = false;
};

ProcessSample sampleProcess(pid_t pid) {
  ProcessSample sample;
  std::FILE* stat = std::fopen(("/proc/" + std::to_string(pid) + "/stat").c_str(), "r");
  if (stat == nullptr) return sample;
  char text[1024] = {};
  const std::size_t n = std::fread(text, 1, sizeof text - 1, stat);
  std::fclose(stat);
  const char* close = std::strrchr(text, ')');
  const long ticks = sysconf(_SC_CLK_TCK);
  unsigned long utime = 0, stime = 0;
  char state = '?';
  if (n > 0 && close != nullptr && ticks > 0 &&
      std::sscanf(close + 2, "%c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %lu %lu", &state, &utime,
                  &stime) == 3) {
    sample.state = state;
    sample.cpuNs = (utime + stime) * (1'000'000'000ull / static_cast<unsigned long>(ticks));
    sample.known = true;
  }
  return sample;
}

// Why a process that should answer does not, from its state letter; empty if it may run.
std::string notRunningReason(char state) {
  switch (state) {
    case 'T':
      return "stopped (process state T: SIGSTOP or SIGTSTP; SIGCONT resumes it)";
    case 't':
      return "stopped by a debugger or tracer (process state t)";
    default:
      return {};
  }
}

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
    ModuleEnd end{"not started", ""};
  };
  std::string jobLabel(const app::MpiJob& job, pid_t mpirun) const;
  std::optional<std::string> refusedWithoutMpirun() const;
  bool startJob(std::size_t jobIndex, int segmentFd, std::vector<std::string> environment,
                RunOutcome& outcome);
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
  void showProgress(bool final);

 public:
  /// Moves what the modules traced into trace_ (no-op when the run is not traced).
  void drainTraces() {
    for (std::size_t i = 0; i < daemon_.modules().size(); ++i) {
      const auto& slot = daemon_.slot(daemon_.modules()[i].slotIndex);
      if (slot.traceOffset == 0) continue;
      if (trace_.modules.size() != daemon_.modules().size()) {
        trace_.modules.clear();
        for (const auto& m : daemon_.modules()) trace_.modules.push_back(m.id);
      }
      auto& ring = *daemon_.segment().at<ipc::TraceRing>(slot.traceOffset);
      drainTraceRing(ring, static_cast<uint32_t>(i), trace_);
    }
    for (const auto& merge : daemon_.takeTraceMerges()) {
      if (trace_.merges.size() >= kMaxTraceEventsPerHost) break;
      trace_.merges.push_back(merge);
    }
  }
  HostTrace trace_;

  /// Live counters for `vrflow monitor`: raw totals, so that the reader computes rates.
  std::string statsJson() {
    nlohmann::json j;
    j["t_ns"] =
        std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
            .count();
    auto modules = nlohmann::json::array();
    const long page = sysconf(_SC_PAGESIZE);
    for (std::size_t i = 0; i < daemon_.modules().size(); ++i) {
      const auto& module = daemon_.modules()[i];
      const auto& slot = daemon_.slot(module.slotIndex);
      nlohmann::json m;
      m["id"] = module.id;
      m["iterations"] = slot.iterations.load();
      m["state"] = children_[i].alive ? stateName(slot.state.load()) : "ended";
      m["compute_ns"] = slot.computeNs.load();
      m["wait_ns"] = slot.waitNs.load();
      uint64_t cpuNs = 0, rss = 0;
      // A module of an MPI job is its rank's process (it wrote its pid when it joined), not
      // the mpirun it shares with the job's other modules.
      const pid_t pid = processOf(i);
      if (children_[i].alive) {
        cpuNs = sampleProcess(pid).cpuNs;
        std::FILE* statm = std::fopen(("/proc/" + std::to_string(pid) + "/statm").c_str(), "r");
        if (statm != nullptr) {
          unsigned long size = 0, resident = 0;
          if (std::fscanf(statm, "%lu %lu", &size, &resident) == 2)
            rss = resident * static_cast<unsigned long>(page);
          std::fclose(statm);
        }
      }
      m["cpu_ns"] = cpuNs;
      m["rss_bytes"] = rss;
      modules.push_back(m);
    }
    j["modules"] = modules;
    auto connections = nlohmann::json::array();
    for (const auto& q : daemon_.queueSnapshot()) {
      connections.push_back({{"from", q.from},
                             {"to", q.to},
                             {"length", q.length},
                             {"capacity", q.capacity},
                             {"messages", q.messages},
                             {"bytes", q.bytes},
                             {"dropped", q.dropped}});
    }
    j["connections"] = connections;
    j["filters"] = filterStatsJson(daemon_.filterSnapshot());
    return j.dump();
  }
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
  Clock::time_point start_ = Clock::now();
  uint64_t lastIterationSum_ = 0;
  Clock::time_point lastProgress_ = Clock::now();
  Clock::time_point lastDisplay_ = Clock::now();
  std::vector<uint64_t> lastDisplayIterations_;
  bool displayed_ = false;

 public:
  std::vector<ModuleEnd> ends() const {
    std::vector<ModuleEnd> result;
    for (const auto& c : children_) result.push_back(c.end);
    return result;
  }
};

Supervisor::Supervisor(const app::Application& application, const app::Catalog& catalog,
                       const RunOptions& options, daemon::Daemon& daemon,
                       std::vector<app::MpiJob> jobs)
    : application_(application), catalog_(catalog), options_(options), daemon_(daemon) {
  // Modules and slots follow the application's module order (Daemon::create).
  VRFLOW_ASSERT(daemon_.modules().size() == application_.modules.size(),
                "one daemon module per application module");
  jobOf_.assign(daemon_.modules().size(), -1);
  for (auto& job : jobs) {
    if (job.modules.size() < 2) continue;  // one module: a plain process (MPI singleton)
    for (const std::size_t m : job.modules) jobOf_[m] = static_cast<int>(jobs_.size());
    jobs_.push_back(std::move(job));
  }
}

// "MPI job 'water' (modules water:b0, water:b1; host local; mpirun pid 42)".
std::string Supervisor::jobLabel(const app::MpiJob& job, pid_t mpirun) const {
  const auto& first = daemon_.modules()[job.modules.front()];
  return "MPI job '" + job.name + "' (modules " + job.moduleIds(application_) + "; host " +
         first.host + (mpirun > 0 ? "; mpirun pid " + std::to_string(mpirun) : "") + ")";
}

// With VRFLOW_MPIRUN=none nothing that runs as several MPI ranks can start, since only mpirun
// starts them: neither a job of several modules (its modules are the ranks of one mpirun) nor a
// module whose type's mpi-ranks parameter is above 1. The reason, before anything starts.
std::optional<std::string> Supervisor::refusedWithoutMpirun() const {
  const char* mpirun = std::getenv("VRFLOW_MPIRUN");
  if (mpirun == nullptr || std::string(mpirun) != "none") return std::nullopt;
  if (!jobs_.empty()) {
    const app::MpiJob& job = jobs_.front();
    return jobLabel(job, 0) + " cannot start: VRFLOW_MPIRUN=none, but its " +
           std::to_string(job.modules.size()) +
           " modules run as the ranks of one mpirun (unset VRFLOW_MPIRUN, or give each module a "
           "job of its own)";
  }
  for (std::size_t m = 0; m < daemon_.modules().size(); ++m) {
    const auto& module = daemon_.modules()[m];
    if (module.mpiRanks <= 1) continue;
    const app::Module& declared = application_.modules[m];
    const app::ModuleType* type = catalog_.findModule(declared.package, declared.type);
    const std::string param = type != nullptr ? "'" + type->mpiRanksParam + "'" : "mpi-ranks";
    const std::string ranks = std::to_string(module.mpiRanks);
    return "module '" + module.id + "' (host " + module.host +
           ") cannot start: VRFLOW_MPIRUN=none, but its " + param + " = " + ranks + " makes it " +
           ranks + " MPI ranks of one mpirun (unset VRFLOW_MPIRUN, or set " + param + " to 1)";
  }
  return std::nullopt;
}

// Starts every module of jobs_[jobIndex] as one mpirun; false (and `outcome` says why) when it
// cannot start.
bool Supervisor::startJob(std::size_t jobIndex, int segmentFd, std::vector<std::string> environment,
                          RunOutcome& outcome) {
  const app::MpiJob& job = jobs_[jobIndex];
  std::vector<int> slots;
  for (const std::size_t m : job.modules) slots.push_back(daemon_.modules()[m].slotIndex);
  environment.push_back("VRFLOW_MPI_JOB=" + job.name);
  const auto& first = daemon_.modules()[job.modules.front()];
  auto backing = mpiFolder_.path();
  if (!backing) {
    outcome = {kExitRunFailed, "failed", jobLabel(job, 0) + ": " + backing.error().message};
    return false;
  }
  auto pid = spawnMpiJob(first.executable, slots, segmentFd, environment, *backing,
                         options_.moduleMemoryBytes);
  if (!pid) {
    outcome = {kExitRunFailed, "failed", jobLabel(job, 0) + ": " + pid.error().message};
    return false;
  }
  for (const std::size_t m : job.modules) {
    children_[m].pid = *pid;
    children_[m].job = static_cast<int>(jobIndex);
    children_[m].alive = true;
    children_[m].end.exit = "running";
  }
  return true;
}

std::size_t Supervisor::liveCount() const {
  std::size_t n = 0;
  for (const auto& c : children_) n += c.alive ? 1 : 0;
  return n;
}

void Supervisor::reap(RunOutcome& outcome, bool stopping) {
  int status = 0;
  pid_t pid = 0;
  while ((pid = waitpid(-1, &status, WNOHANG)) > 0) {
    // One process: a module, or the mpirun of an MPI job that all its modules share.
    std::string notJoined;    // the first module that never joined, if any
    std::string outOfMemory;  // the first module that ran out of memory, if any
    int job = -1;
    std::size_t first = children_.size();
    for (std::size_t i = 0; i < children_.size(); ++i) {
      Child& child = children_[i];
      if (child.pid != pid || !child.alive) continue;
      child.alive = false;
      child.end.exit = WIFEXITED(status) ? "status " + std::to_string(WEXITSTATUS(status))
                                         : "signal " + std::to_string(WTERMSIG(status));
      daemon_.moduleEnded(static_cast<int>(i));
      const auto& module = daemon_.modules()[i];
      if (notJoined.empty() && daemon_.slot(module.slotIndex).state.load() ==
                                   static_cast<uint32_t>(ipc::ModuleState::Starting)) {
        notJoined = module.id;
      }
      if (daemon_.slot(module.slotIndex).outOfMemory.load() != 0) {
        child.end.cause = memoryCause();
        if (outOfMemory.empty()) outOfMemory = module.id;
      }
      if (first == children_.size()) first = i;
      job = child.job;
    }
    if (first == children_.size()) continue;  // not a process of this run
    const bool clean = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if ((clean && notJoined.empty()) || stopping || outcome.exitCode != kExitOk) continue;
    outcome.exitCode = kExitRunFailed;
    outcome.status = "failed";
    const std::string memory =
        outOfMemory.empty() ? "" : ": module '" + outOfMemory + "' " + memoryCause();
    if (job >= 0) {
      outcome.error = jobLabel(jobs_[static_cast<std::size_t>(job)], pid) + " " +
                      describeMpirunWaitStatus(status) +
                      (notJoined.empty() ? ""
                                         : " before module '" + notJoined +
                                               "' joined the run (it never called "
                                               "Module::init())") +
                      memory;
      continue;
    }
    const Child& child = children_[first];
    const auto& module = daemon_.modules()[first];
    const bool mpirun = child.mpiRanks > 1;
    outcome.error =
        "module '" + module.id + "' (host " + module.host + ", " +
        (mpirun ? std::to_string(child.mpiRanks) + " MPI ranks, mpirun pid "
                : std::string("pid ")) +
        std::to_string(pid) + ") " +
        (mpirun ? describeMpirunWaitStatus(status) : describeWaitStatus(status)) +
        (notJoined.empty() ? "" : " before joining the run (it never called Module::init())") +
        (outOfMemory.empty() ? "" : ": it " + memoryCause());
  }
}

// Why a module that marked itself out of memory failed: "ran out of memory under the module
// memory limit of 64 MiB (--module-memory-limit)", or without a limit, just that.
std::string Supervisor::memoryCause() const {
  if (options_.moduleMemoryBytes == 0) return "ran out of memory (an allocation failed)";
  char text[128];
  std::snprintf(text, sizeof text,
                "ran out of memory under the module memory limit of %.4g MiB "
                "(--module-memory-limit)",
                static_cast<double>(options_.moduleMemoryBytes) / 1048576.0);
  return text;
}

// Every live module finished its iterations long ago but has not exited.
bool Supervisor::lingering(std::string& detail) {
  bool all = liveCount() > 0;
  std::string names;
  for (std::size_t i = 0; i < children_.size() && all; ++i) {
    if (!children_[i].alive) continue;
    const auto& module = daemon_.modules()[i];
    all = daemon_.slot(module.slotIndex).state.load() ==
          static_cast<uint32_t>(ipc::ModuleState::Finished);
    names += (names.empty() ? "'" : ", '") + module.id + "'";
  }
  if (!all) {
    finishedSince_ = Clock::time_point{};
    return false;
  }
  if (finishedSince_ == Clock::time_point{}) finishedSince_ = Clock::now();
  if (secondsSince(finishedSince_) < options_.lingerSeconds) return false;
  detail = "module(s) " + names + " finished but did not exit; stopping them";
  return true;
}

// A module still not attached to the run long after its start (it never called init()).
bool Supervisor::notJoined(std::string& detail) {
  if (secondsSince(start_) < options_.joinSeconds) return false;
  for (std::size_t i = 0; i < children_.size(); ++i) {
    const auto& module = daemon_.modules()[i];
    if (children_[i].alive && daemon_.slot(module.slotIndex).state.load() ==
                                  static_cast<uint32_t>(ipc::ModuleState::Starting)) {
      char text[64];
      std::snprintf(text, sizeof text, "%g s", options_.joinSeconds);
      const int job = children_[i].job;
      const std::string process = job < 0 ? "pid " + std::to_string(children_[i].pid)
                                          : "a rank of MPI job '" +
                                                jobs_[static_cast<std::size_t>(job)].name +
                                                "', mpirun pid " + std::to_string(children_[i].pid);
      detail = "module '" + module.id + "' (host " + module.host + ", " + process +
               ") did not join the run within " + text + " (it never called Module::init())";
      return true;
    }
  }
  return false;
}

// The process of module `module`: its own (it wrote its pid when it joined) when it is a rank
// of an MPI job or of an mpirun of its own, else the one started for it.
pid_t Supervisor::processOf(std::size_t module) const {
  const int32_t own = daemon_.slot(daemon_.modules()[module].slotIndex).pid.load();
  const Child& child = children_[module];
  return (child.job >= 0 || child.mpiRanks > 1) && own > 0 ? own : child.pid;
}

// "waits on input 'in' (from src.out) at iteration 3", as the module's slot tells.
std::string Supervisor::waitDetail(std::size_t module, bool& remote) const {
  const auto& slot = daemon_.slot(daemon_.modules()[module].slotIndex);
  int port = slot.waitingPort.load();
  if (port >= static_cast<int>(std::min<uint32_t>(slot.portCount, ipc::kMaxPortsPerModule)))
    port = -1;
  const auto state = static_cast<ipc::ModuleState>(slot.state.load());
  std::string detail;
  if (port >= 0 && state == ipc::ModuleState::Waiting) {
    const std::string name = portName(slot.ports[port]);
    const app::Application& whole =
        options_.wholeApplication != nullptr ? *options_.wholeApplication : application_;
    detail = "waits on input '" + name + "' (" +
             sourcesOf(whole, application_, daemon_.modules()[module].id, name, remote) + ")";
  } else if (port >= 0) {
    detail = "is blocked sending on '" + portName(slot.ports[port]) + "'";
  } else {
    detail = stateName(slot.state.load());
  }
  return detail + " at iteration " + std::to_string(slot.iterations.load());
}

// No module has finished an iteration for options_.deadlockSeconds: a deadlock (every live
// module blocked in wait() or put(), each process able to run), a stall (a module that does not
// respond: stopped, or spinning while its slot says it waits), or nothing to report yet (a
// module still computing). The processes are sampled twice, a second apart, to tell spinning.
std::optional<RunOutcome> Supervisor::noProgress() {
  uint64_t sum = 0;
  for (std::size_t i = 0; i < children_.size(); ++i) {
    sum += daemon_.slot(daemon_.modules()[i].slotIndex).iterations.load();
  }
  const auto now = Clock::now();
  if (sum != lastIterationSum_ || liveCount() == 0) {
    lastIterationSum_ = sum;
    lastProgress_ = now;
    stallSampledAt_ = Clock::time_point{};
    return std::nullopt;
  }
  const double quiet = std::chrono::duration<double>(now - lastProgress_).count();
  if (quiet < options_.deadlockSeconds) return std::nullopt;
  if (stallSampledAt_ == Clock::time_point{} || secondsSince(stallSampledAt_) < 1.0) {
    if (stallSampledAt_ == Clock::time_point{}) {
      stallCpuNs_.assign(children_.size(), 0);
      for (std::size_t i = 0; i < children_.size(); ++i) {
        if (children_[i].alive) stallCpuNs_[i] = sampleProcess(processOf(i)).cpuNs;
      }
      stallSampledAt_ = now;
    }
    return std::nullopt;
  }
  const double sampled = secondsSince(stallSampledAt_);
  std::string stuck, others;
  bool busy = false, remote = false;
  for (std::size_t i = 0; i < children_.size(); ++i) {
    if (!children_[i].alive) continue;
    const auto& module = daemon_.modules()[i];
    const auto state = static_cast<ipc::ModuleState>(daemon_.slot(module.slotIndex).state.load());
    const bool inWait = state == ipc::ModuleState::Waiting || state == ipc::ModuleState::Putting;
    const pid_t pid = processOf(i);
    const ProcessSample process = sampleProcess(pid);
    const double cpu = process.known && process.cpuNs >= stallCpuNs_[i]
                           ? static_cast<double>(process.cpuNs - stallCpuNs_[i]) / 1e9 / sampled
                           : 0.0;
    std::string why = notRunningReason(process.state);
    if (why.empty() && inWait && cpu > 0.5) {
      char text[96];
      std::snprintf(text, sizeof text, "spinning (%.0f%% CPU, process state %c) instead of waiting",
                    100.0 * cpu, process.state);
      why = text;
    }
    bool ignored = false;
    if (!why.empty()) {
      stuck += (stuck.empty() ? "" : "; ") + std::string("module '") + module.id + "' (host " +
               module.host + ", pid " + std::to_string(pid) + ") is not responding: it is " + why +
               " (its slot says: " + waitDetail(i, ignored) + ")";
    } else if (!inWait) {
      busy = true;  // computing (or starting, finishing): it may yet progress
    } else {
      others += (others.empty() ? "" : "; ") + std::string("module '") + module.id + "' " +
                waitDetail(i, remote);
    }
  }
  char quietText[64];
  std::snprintf(quietText, sizeof quietText, "%g s", options_.deadlockSeconds);
  const auto& header = daemon_.segment().header();
  const uint64_t failed = header.failedAllocations.load();
  if (failed > 0 && stuck.empty() && !busy) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "shared memory exhausted: %llu allocation(s) failed in the %.3g MiB segment; "
                  "no module progressed for %s since (raise --shm-size): ",
                  static_cast<unsigned long long>(failed),
                  static_cast<double>(header.size) / 1048576.0, quietText);
    return RunOutcome{kExitRunFailed, "failed", text + others};
  }
  if (!stuck.empty()) {
    return RunOutcome{kExitRunFailed, "stalled",
                      std::string("stalled: no module progressed for ") + quietText + ": " + stuck +
                          (others.empty() ? "" : "; waiting on it: " + others)};
  }
  // Still computing: look again in a second.
  // Waiting on another host: its daemon judges its own modules first (a stopped module there
  // is named by it), so this host gives it time before it calls the run a deadlock.
  const double remoteGrace = std::max(2.0, options_.deadlockSeconds / 2);
  if (busy || (remote && quiet < options_.deadlockSeconds + remoteGrace)) {
    stallSampledAt_ = Clock::time_point{};
    return std::nullopt;
  }
  return RunOutcome{kExitRunFailed, "deadlock",
                    std::string("deadlock: no module progressed for ") + quietText +
                        " and every module is blocked in wait() or put(): " + others};
}

void Supervisor::showProgress(bool final) {
  if (!options_.progress) return;
  const auto now = Clock::now();
  const double dt = std::chrono::duration<double>(now - lastDisplay_).count();
  if (!final && dt < 1.0) return;
  std::string line = "\r[vrflow " + std::to_string(static_cast<int>(secondsSince(start_))) + "s]";
  lastDisplayIterations_.resize(children_.size(), 0);
  for (std::size_t i = 0; i < children_.size(); ++i) {
    const auto& module = daemon_.modules()[i];
    const uint64_t it = daemon_.slot(module.slotIndex).iterations.load();
    const double rate = dt > 0 ? static_cast<double>(it - lastDisplayIterations_[i]) / dt : 0.0;
    lastDisplayIterations_[i] = it;
    char text[128];
    std::snprintf(text, sizeof text, "  %s %.0f it/s", module.id.c_str(), rate);
    line += text;
  }
  winsize ws{};
  if (ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 10 && line.size() > ws.ws_col) {
    line.resize(ws.ws_col);
  }
  line += "\033[K";
  std::fputs(line.c_str(), stderr);
  if (final) std::fputs("\n", stderr);
  displayed_ = true;
  lastDisplay_ = now;
}

void Supervisor::stopAll() {
  daemon_.requestStop();
  RunOutcome ignored;
  const auto graceEnd = Clock::now() + std::chrono::duration<double>(options_.stopGraceSeconds);
  while (liveCount() > 0 && Clock::now() < graceEnd) {
    reap(ignored, true);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  for (int round = 0; round < 2 && liveCount() > 0; ++round) {
    const int sig = round == 0 ? SIGTERM : SIGKILL;
    std::vector<pid_t> signalled;  // the modules of an MPI job share one mpirun
    for (auto& child : children_) {
      if (!child.alive ||
          std::find(signalled.begin(), signalled.end(), child.pid) != signalled.end()) {
        continue;
      }
      kill(-child.pid, sig);                          // its whole process group: wrappers too
      if (sig == SIGTERM) kill(-child.pid, SIGCONT);  // a stopped module takes it too
      signalled.push_back(child.pid);
    }
    const auto end = Clock::now() + std::chrono::seconds(1);
    while (liveCount() > 0 && (round == 1 || Clock::now() < end)) {
      reap(ignored, true);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
}

RunOutcome Supervisor::run() {
  RunOutcome outcome;
  // Signals are blocked (by runApplication) and taken synchronously here; module processes
  // restore them before exec.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGCHLD);
  if (auto refused = refusedWithoutMpirun()) return {kExitRunFailed, "failed", *refused};
  removeStaleMpiBackingFolders();  // of runtimes killed with SIGKILL
  if (auto status = daemon_.start(); !status) {
    return {kExitRunFailed, "failed", status.error().message};
  }
  const int fd = daemon_.segment().fd();
  children_.resize(daemon_.modules().size());
  for (std::size_t i = 0; i < daemon_.modules().size(); ++i) {
    if (children_[i].alive) continue;  // started with its MPI job
    const auto& module = daemon_.modules()[i];
    std::vector<std::string> environment{"VRFLOW_SEGMENT_FD=" + std::to_string(fd),
                                         "VRFLOW_MODULE_INDEX=" + std::to_string(module.slotIndex),
                                         "VRFLOW_MODULE_ID=" + module.id,
                                         "VRFLOW_HOST=" + module.host};
    if (jobOf_[i] >= 0) {
      if (!startJob(static_cast<std::size_t>(jobOf_[i]), fd, environment, outcome)) break;
      continue;
    }
    const bool viaMpirun = module.mpiRanks > 1;  // VRFLOW_MPIRUN=none: refused above
    auto backing = viaMpirun ? mpiFolder_.path() : Result<std::string>(std::string());
    if (!backing) {
      outcome = {kExitRunFailed, "failed",
                 "module '" + module.id + "': " + backing.error().message};
      break;
    }
    auto pid =
        viaMpirun ? spawnMpiModule(module.executable, module.mpiRanks, fd, environment, *backing,
                                   options_.moduleMemoryBytes)
                  : spawnModule(module.executable, {}, fd, environment, options_.moduleMemoryBytes);
    if (!pid) {
      outcome = {kExitRunFailed, "failed", "module '" + module.id + "': " + pid.error().message};
      break;
    }
    children_[i].pid = *pid;
    children_[i].mpiRanks = viaMpirun ? module.mpiRanks : 0;
    children_[i].alive = true;
    children_[i].end.exit = "running";
  }

  while (outcome.exitCode == kExitOk && liveCount() > 0) {
    timespec tick{0, 50'000'000};
    siginfo_t info{};
    const int sig = sigtimedwait(&signals, &info, &tick);
    if (sig == SIGINT || sig == SIGTERM) {
      outcome = {kExitInterrupted, "interrupted",
                 std::string("interrupted by ") + (sig == SIGINT ? "SIGINT" : "SIGTERM")};
      break;
    }
    reap(outcome, false);
    showProgress(false);
    drainTraces();
    if (options_.hostLink != nullptr && secondsSince(lastStats_) >= 1.0) {
      options_.hostLink->stats(statsJson());
      lastStats_ = Clock::now();
    }
    if (options_.timeoutSeconds > 0 && secondsSince(start_) > options_.timeoutSeconds) {
      char text[96];
      std::snprintf(text, sizeof text, "timed out after %g s (--timeout)", options_.timeoutSeconds);
      outcome = {kExitTimeout, "timeout", text};
      break;
    }
    if (options_.hostLink != nullptr) {
      if (auto stop = options_.hostLink->poll()) {
        outcome = *stop;
        break;
      }
    }
    if (auto fatal = daemon_.fatalError(); !fatal.empty()) {
      outcome = {kExitRunFailed, "failed", fatal};
      break;
    }
    std::string detail;
    if (lingering(detail)) {
      std::fprintf(stderr, "vrflow: warning: %s\n", detail.c_str());
      break;  // their work is done: stopAll() ends them, and the run counts as a success
    }
    if (notJoined(detail)) {
      outcome = {kExitRunFailed, "failed", detail};
      break;
    }
    if (outcome.exitCode == kExitOk) {
      if (auto stalled = noProgress()) outcome = *stalled;
    }
  }
  if (displayed_) showProgress(true);
  stopAll();
  return outcome;
}

}  // namespace

Result<app::Catalog> loadCatalog(const std::vector<std::string>& extraDirs) {
  std::vector<std::string> dirs = extraDirs;
  for (const auto& d : app::searchPathFromEnvironment()) dirs.push_back(d);
  if (const auto bin = executableDir(); !bin.empty()) {
    dirs.push_back((bin.parent_path() / "share/vrflow/packages").string());
  }
  app::Catalog catalog = daemon::makeCatalog();
  if (auto status = catalog.loadSearchPath(dirs); !status) return status.error();
  const auto plugins = daemon::filterPluginsFromEnvironment();
  if (auto status = daemon::loadFilterPlugins(plugins, catalog); !status) return status.error();
  return catalog;
}

std::map<std::string, uint64_t, std::less<>> moduleIterations(const app::Application& application,
                                                              uint64_t outer) {
  std::map<std::string, uint64_t, std::less<>> limits;
  const auto rates = app::iterationRates(application, app::resolveGraph(application));
  for (std::size_t m = 0; m < application.modules.size(); ++m) {
    limits[application.modules[m].id] = rates[m].scale(outer);
  }
  return limits;
}

RunOutcome runApplication(const app::Application& application, const app::Catalog& catalog,
                          const RunOptions& options) {
  daemon::DaemonOptions daemonOptions;
  daemonOptions.segmentBytes = options.segmentBytes;
  daemonOptions.iterationLimit = options.iterations;
  daemonOptions.moduleIterationLimits = options.moduleIterations.empty() && options.iterations > 0
                                            ? moduleIterations(application, options.iterations)
                                            : options.moduleIterations;
  daemonOptions.trace = options.trace || !options.tracePath.empty();
  if (!application.hosts.empty()) {
    if (auto id = msg::hostIdFromAddress(application.hosts.front().address)) {
      daemonOptions.hostId = *id;
    }
  }
  if (options.hostLink != nullptr) options.hostLink->configure(daemonOptions);
  // The daemon thread must not take the signals meant for the supervisor: block them before
  // it is created (it inherits this mask).
  sigset_t signals, previous;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGCHLD);
  pthread_sigmask(SIG_BLOCK, &signals, &previous);

  auto daemon = daemon::Daemon::create(application, catalog, daemonOptions);
  if (!daemon) {
    pthread_sigmask(SIG_SETMASK, &previous, nullptr);
    return {kExitRunFailed, "failed", daemon.error().message};
  }
  const auto start = Clock::now();
  Supervisor supervisor(application, catalog, options, **daemon,
                        app::mpiJobs(application, catalog));
  RunOutcome outcome;
  if (options.hostLink != nullptr) {
    if (auto status = options.hostLink->ready(); !status) {
      outcome = {kExitRunFailed, "failed", status.error().message};
    }
  }
  if (outcome.exitCode == kExitOk) outcome = supervisor.run();
  std::vector<std::string> drainWarnings;
  if (options.hostLink != nullptr) drainWarnings = options.hostLink->drain(outcome);
  (*daemon)->shutdown();
  // --iterations N: a module short of its count fails the run, naming it and why.
  if (const std::string cut = shortModules(**daemon); outcome.exitCode == kExitOk && !cut.empty()) {
    outcome = {kExitRunFailed, "short", "ended short of --iterations: " + cut};
  }
  supervisor.drainTraces();
  for (std::size_t i = 0; i < (*daemon)->modules().size(); ++i) {
    const auto& slot = (*daemon)->slot((*daemon)->modules()[i].slotIndex);
    if (slot.traceOffset != 0) {
      supervisor.trace_.dropped +=
          (*daemon)->segment().at<ipc::TraceRing>(slot.traceOffset)->dropped.load();
    }
  }
  if (daemonOptions.trace) {
    if (supervisor.trace_.modules.empty()) {
      for (const auto& m : (*daemon)->modules()) supervisor.trace_.modules.push_back(m.id);
    }
    supervisor.trace_.host = application.hosts.empty() ? "localhost" : application.hosts.front().id;
    if (options.hostLink != nullptr) {
      options.hostLink->trace(hostTraceToJson(supervisor.trace_));
    } else if (!options.tracePath.empty()) {
      std::ofstream out(options.tracePath);
      out << chromeTrace(application, {supervisor.trace_}) << "\n";
      if (!out && outcome.exitCode == kExitOk) {
        outcome = {kExitRunFailed, "failed", "cannot write the trace '" + options.tracePath + "'"};
      }
    }
  }
  std::vector<std::string> warnings = (*daemon)->takeWarnings();
  warnings.insert(warnings.end(), drainWarnings.begin(), drainWarnings.end());
  if (options.hostLink != nullptr) {
    options.hostLink->report(reportJson(application, **daemon, supervisor.ends(), outcome, options,
                                        secondsSince(start), warnings));
  }
  if (!options.reportPath.empty()) {
    auto status = writeReport(options.reportPath, application, **daemon, supervisor.ends(), outcome,
                              options, secondsSince(start), warnings);
    if (!status && outcome.exitCode == kExitOk) {
      outcome = {kExitRunFailed, "failed", status.error().message};
    }
  }
  for (const auto& w : warnings) std::fprintf(stderr, "vrflow: warning: %s\n", w.c_str());
  // Signals that arrived while stopping are consumed here, not delivered on unblocking.
  timespec zero{0, 0};
  while (sigtimedwait(&signals, nullptr, &zero) > 0) {
  }
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  return outcome;
}

}  // namespace vrflow::run
