#include "report.hpp"

#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "vrflow/base/version.hpp"
#include "vrflow/run/report_head.hpp"

namespace vrflow::run {
namespace {

double percentileMs(const ipc::ModuleSlotDaemon& slot, double fraction) {
  uint64_t total = 0;
  for (int b = 0; b < ipc::kHistogramBuckets; ++b) total += slot.histogramCount(b);
  if (total == 0) return 0.0;
  const auto target = static_cast<uint64_t>(fraction * static_cast<double>(total) + 0.999999);
  uint64_t seen = 0;
  for (int b = 0; b < ipc::kHistogramBuckets; ++b) {
    seen += slot.histogramCount(b);
    if (seen >= target) return static_cast<double>(ipc::histogramUpperNs(b)) / 1e6;
  }
  return 0.0;
}

std::string hex(uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
  return text;
}

}  // namespace

void recordExit(ModuleEnd& end, int waitStatus) {
  end.exitCode.reset();
  end.signal.reset();
  if (WIFEXITED(waitStatus)) {
    end.exitCode = WEXITSTATUS(waitStatus);
    end.exit = "status " + std::to_string(*end.exitCode);
  } else {
    end.signal = WTERMSIG(waitStatus);
    end.exit = "signal " + std::to_string(*end.signal);
  }
}

std::string endCauseName(uint32_t cause) {
  switch (static_cast<ipc::EndCause>(cause)) {
    case ipc::EndCause::IterationLimit:
      return "iteration count";
    case ipc::EndCause::EndOfInput:
      return "end of input";
    case ipc::EndCause::LeftLoop:
      return "left its loop";
    case ipc::EndCause::RunStopped:
      return "run stopped";
    case ipc::EndCause::Unneeded:
      return "outputs unneeded";
    case ipc::EndCause::Running:
      break;
  }
  return "none";
}

nlohmann::ordered_json filterStatsJson(const std::vector<daemon::FilterStats>& filters) {
  using nlohmann::ordered_json;
  const auto ports = [](const std::vector<daemon::FilterPortStats>& list) {
    ordered_json array = ordered_json::array();
    for (const auto& p : list) {
      ordered_json dropped = ordered_json::object();
      uint64_t total = 0;
      for (const auto& [reason, count] : p.dropped) {
        dropped[reason] = count;
        total += count;
      }
      array.push_back({{"port", p.port},
                       {"messages", p.messages},
                       {"dropped", total},
                       {"dropped_by_reason", dropped}});
    }
    return array;
  };
  ordered_json array = ordered_json::array();
  for (const auto& f : filters) {
    if (f.type == "port-output") continue;  // forwards every message: see "outputs"
    ordered_json j;
    j["id"] = f.id;
    j["type"] = f.type;
    j["inputs"] = ports(f.inputs);
    j["outputs"] = ports(f.outputs);
    array.push_back(j);
  }
  return array;
}

std::string shortModules(daemon::Daemon& daemon) {
  std::string text;
  for (const auto& module : daemon.modules()) {
    const ipc::ModuleSlotDaemon slot = daemon.slot(module.slotIndex);
    const uint64_t done = slot.iterations();
    const auto cause = static_cast<uint32_t>(slot.endCause());
    // Stopped by the run (an error or Ctrl-C, reported as such) or unneeded: not short.
    const bool counts = cause == static_cast<uint32_t>(ipc::EndCause::EndOfInput) ||
                        cause == static_cast<uint32_t>(ipc::EndCause::LeftLoop);
    if (slot.iterationLimit() == 0 || done >= slot.iterationLimit() || !counts) continue;
    // A filter or connection that dropped messages on the way explains a short input (a gate,
    // decimate; the report's "filters" and "connections" count them).
    if (cause == static_cast<uint32_t>(ipc::EndCause::EndOfInput) &&
        daemon.droppedUpstreamOf(module.slotIndex)) {
      continue;
    }
    text += (text.empty() ? "" : "; ") + std::string("module '") + module.id + "' did " +
            std::to_string(done) + " of " + std::to_string(slot.iterationLimit()) +
            " iterations (" + endCauseName(cause) + ")";
  }
  return text;
}

nlohmann::ordered_json reportHead(const app::Application& application, const RunOutcome& outcome,
                                  uint64_t iterationsRequested) {
  nlohmann::ordered_json report;
  report["format"] = "vrflow-run-report/1";
  report["vrflow_version"] = versionText();
  report["application"] = application.name;
  report["file"] = application.file;
  report["status"] = outcome.status;
  report["exit_code"] = outcome.exitCode;
  report["error"] = outcome.error;
  // The failed module's last lines (a Python module's traceback), as printed after the error.
  if (!outcome.detail.empty()) report["error_detail"] = outcome.detail;
  report["iterations_requested"] = iterationsRequested;
  return report;
}

std::string reportJson(const app::Application& application, daemon::Daemon& daemon,
                       const std::vector<ModuleEnd>& ends, const RunOutcome& outcome,
                       const RunOptions& options, double wallSeconds,
                       const std::vector<std::string>& warnings) {
  using nlohmann::ordered_json;
  ordered_json report = reportHead(application, outcome, options.iterations);

  ordered_json modules = ordered_json::array();
  for (std::size_t i = 0; i < daemon.modules().size(); ++i) {
    const auto& module = daemon.modules()[i];
    const ipc::ModuleSlotDaemon slot = daemon.slot(module.slotIndex);
    const uint64_t iterations = slot.iterations();
    ordered_json m;
    m["id"] = module.id;
    m["host"] = module.host;
    m["iterations"] = iterations;
    m["exit_code"] = nullptr;
    m["signal"] = nullptr;
    if (i >= ends.size()) {
      m["exit"] = "not started";  // stopped before "go"
    } else {
      m["exit"] = ends[i].exit;
      if (ends[i].exitCode) m["exit_code"] = *ends[i].exitCode;
      if (ends[i].signal) m["signal"] = *ends[i].signal;
      if (!ends[i].cause.empty()) m["cause"] = ends[i].cause;
    }
    m["end"] = endCauseName(static_cast<uint32_t>(slot.endCause()));
    ordered_json timing;
    const double computeS = static_cast<double>(slot.computeNs()) / 1e9;
    timing["iteration_ms_mean"] =
        iterations ? computeS * 1e3 / static_cast<double>(iterations) : 0.0;
    timing["iteration_ms_p99"] = percentileMs(slot, 0.99);
    timing["compute_s"] = computeS;
    timing["wait_s"] = static_cast<double>(slot.waitNs()) / 1e9;
    m["timing"] = timing;
    modules.push_back(m);
  }
  report["modules"] = modules;

  ordered_json connections = ordered_json::array();
  for (const auto& c : daemon.connectionStats()) {
    ordered_json j;
    j["from"] = c.from;
    j["to"] = c.to;
    j["messages"] = c.messages;
    j["bytes"] = c.bytes;
    j["dropped"] = c.dropped;
    j["stayed_full"] = c.stayedFull;
    connections.push_back(j);
  }
  report["connections"] = connections;
  report["filters"] = filterStatsJson(daemon.filterStats());

  ordered_json outputs = ordered_json::array();
  for (const auto& o : daemon.outputStats()) {
    ordered_json j;
    j["module"] = o.module;
    j["port"] = o.port;
    j["messages"] = o.messages;
    if (o.hasLast) {
      j["last_iteration"] = o.lastIteration;
      j["last_digest"] = hex(o.lastDigest);
    } else {
      j["last_iteration"] = nullptr;
      j["last_digest"] = nullptr;
    }
    outputs.push_back(j);
  }
  report["outputs"] = outputs;
  report["warnings"] = warnings;
  ordered_json timing;
  timing["wall_s"] = wallSeconds;
  timing["segment_peak_bytes"] = daemon.segment().header().peakInUseBytes.load();
  report["timing"] = timing;
  return report.dump(2);
}

Status writeReport(const std::string& path, const app::Application& application,
                   daemon::Daemon& daemon, const std::vector<ModuleEnd>& ends,
                   const RunOutcome& outcome, const RunOptions& options, double wallSeconds,
                   const std::vector<std::string>& warnings) {
  const std::string text =
      reportJson(application, daemon, ends, outcome, options, wallSeconds, warnings);
  std::ofstream out(path);
  if (!out) return makeError("cannot write the report '" + path + "'");
  out << text << "\n";
  if (!out) return makeError("cannot write the report '" + path + "'");
  return {};
}

}  // namespace vrflow::run
