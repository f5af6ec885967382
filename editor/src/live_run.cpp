#include "live_run.hpp"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "vrflow/editor/analysis.hpp"

namespace vrflow::editor::gui {

namespace {

using nlohmann::json;

constexpr double kHistorySeconds = 60;

uint64_t count(const json& object, const char* key) {
  const auto it = object.find(key);
  return it != object.end() && it->is_number() ? it->get<uint64_t>() : 0;
}

std::string text(const json& object, const char* key) {
  const auto it = object.find(key);
  return it != object.end() && it->is_string() ? it->get<std::string>() : std::string();
}

// The host a line "host 'b': ..." names, or empty.
std::string hostNamedIn(const std::string& line) {
  const std::string prefix = "host '";
  const auto at = line.find(prefix);
  if (at == std::string::npos) return {};
  const auto end = line.find('\'', at + prefix.size());
  return end == std::string::npos ? std::string()
                                  : line.substr(at + prefix.size(), end - at - prefix.size());
}

}  // namespace

HostLive* LiveRun::host(const std::string& id) {
  for (auto& h : hosts) {
    if (h.id == id) return &h;
  }
  return nullptr;
}

std::string LiveRun::summary() const {
  char line[160];
  switch (phase) {
    case Phase::None:
      return "No run";
    case Phase::Running:
      std::snprintf(line, sizeof line, "Running: %.1f s", time);
      return line;
    case Phase::Ended:
      break;
  }
  if (status == "ok") {
    uint64_t most = 0;
    for (const auto& [id, module] : modules) most = std::max(most, module.iterations);
    std::snprintf(line, sizeof line, "Finished: %llu iterations in %.1f s",
                  static_cast<unsigned long long>(most), time);
    return line;
  }
  std::string out = status == "interrupted" ? "Stopped" : "Failed";
  if (!status.empty() && status != "failed" && status != "interrupted") out += " (" + status + ")";
  if (!error.empty()) out += ": " + error;
  out += " [exit " + std::to_string(exitCode) + "]";
  return out;
}

void LiveRunModel::reset() {
  run_ = LiveRun{};
  lastStatsTime_ = -1;
  lastStatsTimeOfHost_.clear();
  previous_.clear();
  badLines_ = 0;
}

void LiveRunModel::handleLine(const QByteArray& line) {
  const json event = json::parse(line.constData(), line.constData() + line.size(), nullptr, false);
  if (!event.is_object() || !event.contains("event") || !event["event"].is_string()) {
    ++badLines_;
    return;
  }
  const std::string kind = event["event"].get<std::string>();
  if (event.contains("time") && event["time"].is_number()) run_.time = event["time"].get<double>();

  if (kind == "started") {
    run_.phase = LiveRun::Phase::Running;
    run_.application = text(event, "application");
    run_.file = text(event, "file");
    if (event.contains("hosts") && event["hosts"].is_array()) {
      for (const auto& h : event["hosts"]) {
        if (!h.is_object()) continue;
        HostLive host;
        host.id = text(h, "id");
        host.address = text(h, "address");
        if (!run_.host(host.id)) run_.hosts.push_back(std::move(host));
      }
    }
    if (event.contains("modules") && event["modules"].is_array()) {
      for (const auto& m : event["modules"]) {
        if (!m.is_object()) continue;
        auto& module = run_.modules[text(m, "id")];
        module.id = text(m, "id");
        module.type = text(m, "type");
        module.host = text(m, "host");
        module.state = "starting";
      }
    }
  } else if (kind == "stats") {
    if (run_.phase == LiveRun::Phase::None) run_.phase = LiveRun::Phase::Running;
    const std::string statsHost = text(event, "host");
    double& last = statsHost.empty() ? lastStatsTime_ : lastStatsTimeOfHost_[statsHost];
    const double dt = last >= 0 ? run_.time - last : 0;
    last = run_.time;
    const std::size_t keep =
        static_cast<std::size_t>(kHistorySeconds / std::max(dt > 0 ? dt : 1.0, 0.05));
    if (event.contains("modules") && event["modules"].is_array()) {
      for (const auto& m : event["modules"]) {
        if (!m.is_object()) continue;
        auto& module = run_.modules[text(m, "id")];
        if (module.id.empty()) module.id = text(m, "id");
        if (module.host.empty()) module.host = statsHost;
        const uint64_t iterations = count(m, "iterations");
        const Totals now{count(m, "compute_ns"), count(m, "wait_ns"), count(m, "cpu_ns")};
        const auto before = previous_.find(module.id);
        if (dt > 0 && before != previous_.end()) {
          const Totals& was = before->second;
          module.rate =
              static_cast<double>(iterations - std::min(iterations, module.iterations)) / dt;
          const auto delta = [](uint64_t a, uint64_t b) {
            return static_cast<double>(a - std::min(a, b));
          };
          const double compute = delta(now.compute, was.compute), wait = delta(now.wait, was.wait);
          module.waitShare = compute + wait > 0 ? wait / (compute + wait) : 0;
          module.cpu = delta(now.cpu, was.cpu) / 1e9 / dt;
        }
        previous_[module.id] = now;
        module.iterations = iterations;
        module.state = text(m, "state");
        module.rssMiB = static_cast<double>(count(m, "rss_bytes")) / 1048576.0;
        if (dt > 0) {
          module.history.push_back(module.rate);
          while (module.history.size() > keep) module.history.pop_front();
        }
      }
    }
  } else if (kind == "warning") {
    run_.warnings.push_back(text(event, "text"));
  } else if (kind == "module_exit") {
    auto& module = run_.modules[text(event, "module")];
    if (module.id.empty()) module.id = text(event, "module");
    if (module.host.empty()) module.host = text(event, "host");
    module.state = "exited";
    module.exit = text(event, "exit");
    const std::string cause = text(event, "cause");
    if (!cause.empty()) module.failure = cause;
  } else if (kind == "end") {
    run_.phase = LiveRun::Phase::Ended;
    run_.exitCode = event.contains("exit_code") && event["exit_code"].is_number_integer()
                        ? event["exit_code"].get<int>()
                        : -1;
    run_.status = text(event, "status");
    run_.error = text(event, "error");
    if (!run_.error.empty()) {
      const std::string failed = moduleNamedIn(run_.error);
      if (!failed.empty() && run_.modules.count(failed)) run_.modules[failed].failure = run_.error;
      if (HostLive* h = run_.host(hostNamedIn(run_.error))) {
        h->cause = run_.error;
        h->lost = run_.error.find("lost") != std::string::npos;
      }
    }
    Q_EMIT changed();
    Q_EMIT ended();
    return;
  } else {
    return;  // a kind this editor does not know: later versions may add some
  }
  Q_EMIT changed();
}

}  // namespace vrflow::editor::gui
