// Why a run does not progress: a deadlock (every module blocked in wait() or put()), a stall
// (a module that does not respond), a module that never joins, modules that never leave.
#include <unistd.h>

#include <cstdio>
#include <cstring>

#include "supervisor.hpp"

namespace vrflow::run::detail {
namespace {

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

}  // namespace

const char* stateName(ipc::ModuleState state) {
  switch (state) {
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

// Every live module finished its iterations long ago but has not exited.
bool Supervisor::lingering(std::string& detail) {
  bool all = liveCount() > 0;
  std::string names;
  for (std::size_t i = 0; i < children_.size() && all; ++i) {
    if (!children_[i].alive) continue;
    const auto& module = daemon_.modules()[i];
    all = daemon_.slot(module.slotIndex).finished();
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
    if (children_[i].alive &&
        daemon_.slot(module.slotIndex).state() == ipc::ModuleState::Starting) {
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
  const int32_t own = daemon_.slot(daemon_.modules()[module].slotIndex).pid();
  const Child& child = children_[module];
  return (child.job >= 0 || child.mpiRanks > 1) && own > 0 ? own : child.pid;
}

// "waits on input 'in' (from src.out) at iteration 3", as the module's slot tells.
std::string Supervisor::waitDetail(std::size_t module, bool& remote) const {
  const auto slot = daemon_.slot(daemon_.modules()[module].slotIndex);
  const int port = slot.waitingPort();
  const auto state = slot.state();
  std::string detail;
  if (port >= 0 && state == ipc::ModuleState::Waiting) {
    const std::string name = slot.portName(port);
    const app::Application& whole =
        options_.wholeApplication != nullptr ? *options_.wholeApplication : application_;
    detail = "waits on input '" + name + "' (" +
             sourcesOf(whole, application_, daemon_.modules()[module].id, name, remote) + ")";
  } else if (port >= 0) {
    detail = "is blocked sending on '" + slot.portName(port) + "'";
  } else {
    detail = stateName(state);
  }
  return detail + " at iteration " + std::to_string(slot.iterations());
}

// No module has finished an iteration for options_.deadlockSeconds: a deadlock (every live
// module blocked in wait() or put(), each process able to run), a stall (a module that does not
// respond: stopped, or spinning while its slot says it waits), or nothing to report yet (a
// module still computing). The processes are sampled twice, a second apart, to tell spinning.
std::optional<RunOutcome> Supervisor::noProgress() {
  uint64_t sum = 0;
  for (std::size_t i = 0; i < children_.size(); ++i) {
    sum += daemon_.slot(daemon_.modules()[i].slotIndex).iterations();
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
    const auto state = daemon_.slot(module.slotIndex).state();
    const bool inWait = state == ipc::ModuleState::Waiting || state == ipc::ModuleState::Putting;
    const pid_t pid = processOf(i);
    const ProcessSample process = sampleProcess(pid);
    const double cpu = process.known && process.cpuNs >= stallCpuNs_[i]
                           ? static_cast<double>(process.cpuNs - stallCpuNs_[i]) / 1e9 / sampled
                           : 0.0;
    // A module that finished is exiting: a sanitizer's leak check stops it under a tracer
    // (state t) for a while, which is no stall of the run.
    std::string why =
        state == ipc::ModuleState::Finished ? std::string() : notRunningReason(process.state);
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

}  // namespace vrflow::run::detail
