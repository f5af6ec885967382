#include "supervisor.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <thread>

#include "vrflow/base/assert.hpp"
#include "vrflow/run/events.hpp"
#include "vrflow/run/log.hpp"

namespace vrflow::run::detail {

Supervisor::Supervisor(const app::Application& application, const app::Catalog& catalog,
                       const RunOptions& options, daemon::Daemon& daemon,
                       std::vector<app::MpiJob> jobs)
    : application_(application),
      catalog_(catalog),
      options_(options),
      daemon_(daemon),
      // Under the launcher the lines go to it (which prints them), not to this host's stderr.
      logs_({.logDir = options.logDir,
             .echo = options.hostLink == nullptr,
             .colour = options.hostLink == nullptr && ModuleLogs::colourOnTerminal(),
             .forward =
                 options.hostLink == nullptr
                     ? std::function<void(const std::string&, std::string_view)>()
                     : [link = options.hostLink](const std::string& module, std::string_view text) {
                         link->output(module, text);
                       }}) {
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
bool Supervisor::startJob(std::size_t jobIndex, ipc::JoinContract contract, RunOutcome& outcome) {
  const app::MpiJob& job = jobs_[jobIndex];
  std::vector<int> slots;
  for (const std::size_t m : job.modules) slots.push_back(daemon_.modules()[m].slotIndex);
  contract.mpiJob = job.name;
  const auto& first = daemon_.modules()[job.modules.front()];
  auto backing = mpiFolder_.path();
  if (!backing) {
    outcome = {kExitRunFailed, "failed", jobLabel(job, 0) + ": " + backing.error().message};
    return false;
  }
  std::vector<std::size_t> logIndices;
  for (const std::size_t m : job.modules) logIndices.push_back(logIndex_[m]);
  const int output = outputPipe(logIndices, /*mpiTagged=*/true, outcome);
  if (output < 0) return false;
  auto pid =
      spawnMpiJob(first.executable, slots, contract, *backing, options_.moduleMemoryBytes, output);
  close(output);
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
      recordExit(child.end, status);
      daemon_.moduleEnded(static_cast<int>(i));
      const auto& module = daemon_.modules()[i];
      if (notJoined.empty() &&
          daemon_.slot(module.slotIndex).state() == ipc::ModuleState::Starting) {
        notJoined = module.id;
      }
      if (daemon_.slot(module.slotIndex).outOfMemory()) {
        child.end.cause = memoryCause();
        if (outOfMemory.empty()) outOfMemory = module.id;
      }
      if (options_.events != nullptr) {
        options_.events->moduleExit(module.id, module.host, child.end.exit, child.end.cause);
      }
      if (first == children_.size()) first = i;
      job = child.job;
      // Its last lines are still in its pipe: failureDetail() reads them after the run.
    }
    if (first == children_.size()) continue;  // not a process of this run
    const bool clean = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if ((clean && notJoined.empty()) || stopping || outcome.exitCode != kExitOk) continue;
    outcome.exitCode = kExitRunFailed;
    outcome.status = "failed";
    failed_ = static_cast<long>(first);
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
  for (const auto& module : daemon_.modules()) {
    auto index = logs_.add(module.id, module.host);
    if (!index) return {kExitRunFailed, "failed", index.error().message};
    logIndex_.push_back(*index);
  }
  for (std::size_t i = 0; i < daemon_.modules().size(); ++i) {
    if (children_[i].alive) continue;  // started with its MPI job
    const auto& module = daemon_.modules()[i];
    ipc::JoinContract contract;
    contract.segmentFd = fd;
    contract.moduleIndex = module.slotIndex;
    contract.moduleId = module.id;
    contract.host = module.host;
    if (jobOf_[i] >= 0) {
      if (!startJob(static_cast<std::size_t>(jobOf_[i]), contract, outcome)) break;
      continue;
    }
    const bool viaMpirun = module.mpiRanks > 1;  // VRFLOW_MPIRUN=none: refused above
    auto backing = viaMpirun ? mpiFolder_.path() : Result<std::string>(std::string());
    if (!backing) {
      outcome = {kExitRunFailed, "failed",
                 "module '" + module.id + "': " + backing.error().message};
      break;
    }
    const int output = outputPipe({logIndex_[i]}, viaMpirun, outcome);
    if (output < 0) break;
    std::vector<std::string> environment = contract.encode();
    environment.insert(environment.end(), module.environment.begin(), module.environment.end());
    auto pid = viaMpirun ? spawnMpiModule(module.executable, module.mpiRanks, contract, *backing,
                                          options_.moduleMemoryBytes, output)
                         : spawnModule(module.executable, module.arguments, fd, environment,
                                       options_.moduleMemoryBytes, output);
    close(output);
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
    showProgress();
    drainTraces();
    publishStats();
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
      logWarning("vrflow: warning: " + detail);
      if (options_.events != nullptr) options_.events->warning(detail);
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
  showProgress(&outcome);
  if (options_.hostLink != nullptr && outcome.exitCode != kExitOk &&
      outcome.exitCode != kExitInterrupted) {
    options_.hostLink->failing(outcome);
  }
  stopAll();
  // Every process ended: what they printed last is read to the end of their pipes (a process
  // they left behind holding one open is waited for briefly).
  output_.finish(/*seconds=*/2);
  if (outcome.exitCode != kExitOk && failed_ >= 0) outcome.detail = failureDetail();
  publishStats(/*now=*/true);  // the final counts, every module ended
  return outcome;
}

int Supervisor::outputPipe(const std::vector<std::size_t>& modules, bool mpiTagged,
                           RunOutcome& outcome) {
  auto fd = output_.add(modules, mpiTagged);
  if (fd) return *fd;
  outcome = {kExitRunFailed, "failed", fd.error().message};
  return -1;
}

std::string Supervisor::failureDetail() const {
  const auto& module = daemon_.modules()[static_cast<std::size_t>(failed_)];
  const std::string file = logs_.logFile(module.id);
  const std::vector<std::string> lines = logs_.lastLines(module.id);
  const std::string log = file.empty() ? "" : " (its log: " + file + ")";
  if (lines.empty()) return "vrflow: module '" + module.id + "' printed nothing" + log;
  std::string text = "vrflow: the last " + std::to_string(lines.size()) + " line" +
                     (lines.size() == 1 ? "" : "s") + " of module '" + module.id + "'" + log + ":";
  for (const auto& line : lines) text += "\n  " + line;
  return text;
}

}  // namespace vrflow::run::detail
