#include "vrflow/launcher/launch.hpp"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/signalfd.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "launcher.hpp"
#include "vrflow/run/events.hpp"
#include "vrflow/run/log.hpp"
#include "vrflow/run/registry.hpp"
#include "vrflow/run/trace.hpp"

namespace vrflow::launcher {
namespace detail {
namespace {

// A daemon answers "stop" with "stopping" from its control reader at once; one that has not
// within this time (frozen, stopped by a signal, swapping) is killed.
constexpr double kStopAnswerSeconds = 0.5;
// A daemon that answered must then exit within this time, or it is killed too.
constexpr double kStopExitSeconds = 8;

}  // namespace

int64_t steadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

void Launcher::failWith(run::RunOutcome outcome, bool rootCause) {
  if (stopping_) return;  // what dies while we stop everything is our doing, not a cause
  // A daemon's own death or a module's failure names the cause better than a peer's
  // "lost the link": keep the first root cause.
  if (failure_ && (failureIsRoot_ || !rootCause)) return;
  if (!failure_) failureAt_ = Clock::now();
  // Said when seen: stopping the other hosts takes a moment, and the cause must not wait for it.
  run::logError("vrflow: " + outcome.error + "; stopping every host");
  failure_ = std::move(outcome);
  failureIsRoot_ = rootCause;
}

void Launcher::stopAll() {
  stopping_ = true;
  for (const auto& d : daemons_) {
    if (!d.exited) d.send(net::ControlCommand::bare(net::ControlCommand::Kind::Stop));
  }
  const auto begin = Clock::now();
  auto allAnswered = [&] {
    for (const auto& d : daemons_) {
      if (!d.exited && !d.stopAnswered) return false;
    }
    return true;
  };
  while (!allAnswered() && secondsSince(begin) < kStopAnswerSeconds) pump(20);
  for (const auto& d : daemons_) {
    if (d.exited || d.stopAnswered) continue;
    char text[64];
    std::snprintf(text, sizeof text, "%g", kStopAnswerSeconds);
    run::logWarning("vrflow: the " + d.name() + " did not answer \"stop\" within " + text +
                    " s: killed");
    kill(-d.pid, SIGKILL);
  }
  while (!allExited() && secondsSince(begin) < kStopExitSeconds) pump(20);
  for (int round = 0; round < 2 && !allExited(); ++round) {
    for (const auto& d : daemons_) {
      if (!d.exited) kill(-d.pid, round == 0 ? SIGTERM : SIGKILL);
    }
    const auto t = Clock::now();
    while (!allExited() && (round == 1 || secondsSince(t) < 2)) pump(20);
  }
  cancelSlurmSteps();  // a killed srun leaves its step (and daemon) running
  // A daemon killed under mpirun may still be tearing down when mpirun is gone: the launcher is
  // their subreaper (run()), so it leaves only once every descendant has exited (5 s at most).
  const auto t = Clock::now();
  for (;;) {
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid < 0 || secondsSince(t) >= 5) break;  // ECHILD: nothing is left
    if (pid == 0) usleep(20'000);
  }
}

void Launcher::showProgress(const run::RunOutcome* end) {
  if (end == nullptr ? !progress_.due() : options_.progress == run::ProgressMode::Off) return;
  if (options_.iterations > 0 && moduleTargets_.empty()) {
    moduleTargets_ = run::moduleIterations(application_, options_.iterations);
  }
  std::vector<run::ModuleProgress> modules;
  for (const auto& d : daemons_) {
    const auto stats = nlohmann::json::parse(d.stats, nullptr, false);
    if (stats.is_discarded() || !stats.contains("modules")) continue;
    for (const auto& m : stats["modules"]) {
      const auto target = moduleTargets_.find(m.value("id", std::string()));
      modules.push_back({m.value("iterations", uint64_t{0}),
                         target != moduleTargets_.end() ? target->second : 0});
    }
  }
  const uint64_t done = run::outerIterationsDone(modules, options_.iterations);
  if (end != nullptr) {
    progress_.finish(done, end->status);
  } else {
    progress_.update(done);
  }
}

run::RunOutcome Launcher::run() {
  sigset_t signals, previous;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGCHLD);
  sigprocmask(SIG_BLOCK, &signals, &previous);
  sigset_t wanted;
  sigemptyset(&wanted);
  sigaddset(&wanted, SIGINT);
  sigaddset(&wanted, SIGTERM);
  signalFd_ = signalfd(-1, &wanted, SFD_CLOEXEC | SFD_NONBLOCK);
  // Orphans of the run (the daemons of an mpirun that died) become our children, to be reaped.
  prctl(PR_SET_CHILD_SUBREAPER, 1);
  const auto begin = Clock::now();
  // Every module has its log file here from the start, even one that prints nothing.
  for (const auto& m : application_.modules) {
    if (auto added = logs_.add(m.id, app::effectiveHost(application_, m.host)); !added) {
      run::logWarning("vrflow: warning: " + added.error().message);
    }
  }
  // The launch registers, its merged events feeding the registry (docs/operations.md).
  std::optional<run::RegisteredRun> registered;
  events_ = options_.events;
  if (!options_.runId.empty()) {
    registered.emplace(run::identityOf(application_, "launch", options_.runId, options_.iterations,
                                       options_.logDir),
                       options_.events);
    events_ = registered->events();
  }

  if (auto status = start(); !status) {
    failWith({run::kExitRunFailed, "failed", status.error().message}, true);
  } else if (events_ != nullptr) {
    events_->started(application_);  // every host said "go"
  }
  bool quitSent = false;
  while (!allExited()) {
    pump(50);
    if (failure_) {
      // Give a root cause (a dead daemon, a failed module) a moment to show before stopping.
      if (!failureIsRoot_ && secondsSince(failureAt_) < 0.5) continue;
      break;
    }
    if (options_.timeoutSeconds > 0 && secondsSince(begin) > options_.timeoutSeconds) {
      char text[96];
      std::snprintf(text, sizeof text, "timed out after %g s (--timeout)", options_.timeoutSeconds);
      failWith({run::kExitTimeout, "timeout", text}, true);
      break;
    }
    showProgress();
    bool allFinished = true;
    for (const auto& d : daemons_) allFinished = allFinished && d.finished;
    if (allFinished && !quitSent) {
      for (const auto& d : daemons_)
        d.send(net::ControlCommand::bare(net::ControlCommand::Kind::Quit));
      quitSent = true;
    }
  }
  stopAll();
  for (auto& d : daemons_) {
    if (d.toDaemon >= 0) close(d.toDaemon);
    if (d.fromDaemon >= 0) close(d.fromDaemon);
  }
  run::RunOutcome outcome = failure_.value_or(run::RunOutcome{});
  showProgress(&outcome);  // every daemon ended: their last statistics are in
  if (!options_.reportPath.empty()) {
    std::vector<std::string> parts;
    for (const auto& d : daemons_) {
      if (!d.report.empty()) parts.push_back(d.report);
    }
    std::ofstream out(options_.reportPath);
    out << mergeReports(application_, parts, outcome, options_.iterations, secondsSince(begin))
        << "\n";
    if (!out && outcome.exitCode == run::kExitOk) {
      outcome = {run::kExitRunFailed, "failed",
                 "cannot write the report '" + options_.reportPath + "'"};
    }
  }
  if (!options_.tracePath.empty()) {
    std::vector<run::HostTrace> traces;
    for (const auto& d : daemons_) {
      if (d.trace.empty()) continue;
      auto trace = run::hostTraceFromJson(d.trace);
      if (!trace) continue;
      trace->host = d.host;
      trace->clockOffsetNs = d.clockOffsetNs;
      traces.push_back(std::move(*trace));
    }
    std::ofstream out(options_.tracePath);
    out << run::chromeTrace(application_, traces) << "\n";
    if (!out && outcome.exitCode == run::kExitOk) {
      outcome = {run::kExitRunFailed, "failed",
                 "cannot write the trace '" + options_.tracePath + "'"};
    }
  }
  close(signalFd_);
  timespec zero{0, 0};
  while (sigtimedwait(&signals, nullptr, &zero) > 0) {
  }
  sigprocmask(SIG_SETMASK, &previous, nullptr);
  if (events_ != nullptr) events_->end(outcome);
  events_ = nullptr;  // the registry's stream ends with `registered`, here
  return outcome;
}

}  // namespace detail

run::RunOutcome launch(const app::Application& application, const LaunchOptions& options) {
  // Mistakes in what the user gave (exit 2, as an invalid application) before anything starts.
  if (auto checked = detail::checkLaunch(application, options); !checked) {
    return {run::kExitInvalid, "failed", checked.error().message};
  }
  detail::Launcher launcher(application, options);
  return launcher.run();
}

}  // namespace vrflow::launcher
