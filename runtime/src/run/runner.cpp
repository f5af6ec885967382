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

#include "supervisor.hpp"
#include "vrflow/app/graph.hpp"
#include "vrflow/app/mpi_job.hpp"
#include "vrflow/base/assert.hpp"
#include "vrflow/daemon/daemon.hpp"
#include "vrflow/run/events.hpp"
#include "vrflow/run/log.hpp"
#include "vrflow/run/registry.hpp"
#include "vrflow/run/trace.hpp"

namespace vrflow::run {

using detail::Clock;
using detail::secondsSince;

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
                          const RunOptions& given) {
  // The daemon thread must not take the signals meant for the supervisor: block them before
  // it is created (it inherits this mask); blocked before the run registers, a SIGTERM from
  // `vrflow stop` always ends it in order.
  sigset_t signals, previous;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGCHLD);
  pthread_sigmask(SIG_BLOCK, &signals, &previous);
  // A run of `vrflow run` (with an id) registers, its events feeding the registry
  // (docs/operations.md); a daemon's share of a launch does not (the launch registers).
  std::optional<RegisteredRun> registered;
  RunOptions options = given;
  if (!given.runId.empty() && given.hostLink == nullptr) {
    registered.emplace(identityOf(application, "run", given.runId, given.iterations, given.logDir),
                       given.events);
    options.events = registered->events();
  }
  daemon::DaemonOptions daemonOptions;
  daemonOptions.segmentBytes = options.segmentBytes;
  daemonOptions.iterationLimit = options.iterations;
  daemonOptions.moduleIterationLimits = options.moduleIterations.empty() && options.iterations > 0
                                            ? moduleIterations(application, options.iterations)
                                            : options.moduleIterations;
  daemonOptions.trace = options.trace || !options.tracePath.empty();
  // Ids are the whole application's, whatever share of it this daemon serves.
  daemonOptions.idPrefixes = daemon::idPrefixesOf(
      options.wholeApplication != nullptr ? *options.wholeApplication : application);
  if (options.hostLink != nullptr) options.hostLink->configure(daemonOptions);

  auto daemon = daemon::Daemon::create(application, catalog, daemonOptions);
  if (!daemon) {
    pthread_sigmask(SIG_SETMASK, &previous, nullptr);
    const RunOutcome failed{kExitRunFailed, "failed", daemon.error().message};
    if (options.events != nullptr) options.events->end(failed);
    return failed;
  }
  const auto start = Clock::now();
  detail::Supervisor supervisor(application, catalog, options, **daemon,
                                app::mpiJobs(application, catalog));
  RunOutcome outcome;
  if (options.hostLink != nullptr) {
    if (auto status = options.hostLink->ready(); !status) {
      outcome = {kExitRunFailed, "failed", status.error().message};
    }
  }
  if (options.events != nullptr)
    options.events->started(options.wholeApplication != nullptr ? *options.wholeApplication
                                                                : application);
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
    if (const ipc::TraceRing* ring =
            (*daemon)->slot((*daemon)->modules()[i].slotIndex).traceRing()) {
      supervisor.trace_.dropped += ring->dropped.load();
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
  for (const auto& w : warnings) {
    logWarning("vrflow: warning: " + w);
    if (options.events != nullptr) options.events->warning(w);
  }
  if (options.events != nullptr) options.events->end(outcome);
  // Signals that arrived while stopping are consumed here, not delivered on unblocking.
  timespec zero{0, 0};
  while (sigtimedwait(&signals, nullptr, &zero) > 0) {
  }
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  return outcome;
}

}  // namespace vrflow::run
