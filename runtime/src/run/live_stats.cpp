// What a run shows while it runs: the progress line for people, the statistics for the
// launcher and the event stream, the modules' traces.
#include <sys/ioctl.h>
#include <unistd.h>

#include <cstdio>
#include <nlohmann/json.hpp>

#include "supervisor.hpp"
#include "vrflow/run/events.hpp"

namespace vrflow::run::detail {

void Supervisor::drainTraces() {
  for (std::size_t i = 0; i < daemon_.modules().size(); ++i) {
    ipc::TraceRing* ring = daemon_.slot(daemon_.modules()[i].slotIndex).traceRing();
    if (ring == nullptr) continue;
    if (trace_.modules.size() != daemon_.modules().size()) {
      trace_.modules.clear();
      for (const auto& m : daemon_.modules()) trace_.modules.push_back(m.id);
    }
    drainTraceRing(*ring, static_cast<uint32_t>(i), trace_);
  }
  for (const auto& merge : daemon_.takeTraceMerges()) {
    if (trace_.merges.size() >= kMaxTraceEventsPerHost) break;
    trace_.merges.push_back(merge);
  }
}

nlohmann::json Supervisor::statsSnapshot() {
  nlohmann::json j;
  j["t_ns"] =
      std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
  auto modules = nlohmann::json::array();
  const long page = sysconf(_SC_PAGESIZE);
  for (std::size_t i = 0; i < daemon_.modules().size(); ++i) {
    const auto& module = daemon_.modules()[i];
    const auto slot = daemon_.slot(module.slotIndex);
    nlohmann::json m;
    m["id"] = module.id;
    m["iterations"] = slot.iterations();
    m["state"] = children_[i].alive ? stateName(slot.state()) : "ended";
    m["compute_ns"] = slot.computeNs();
    m["wait_ns"] = slot.waitNs();
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
  return j;
}

void Supervisor::publishStats(bool now) {
  if (options_.hostLink == nullptr && options_.events == nullptr) return;
  if (!now && secondsSince(lastStats_) < 1.0) return;
  const std::string snapshot = statsSnapshot().dump();
  if (options_.hostLink != nullptr) options_.hostLink->stats(snapshot);
  if (options_.events != nullptr) options_.events->stats(snapshot);
  lastStats_ = Clock::now();
}

void Supervisor::showProgress(bool final) {
  if (!options_.progress) return;
  const auto now = Clock::now();
  const double dt = std::chrono::duration<double>(now - lastDisplay_).count();
  if (!final && dt < 1.0) return;
  std::string line = "\r[vrflow " + std::to_string(static_cast<int>(secondsSince(start_))) + "s]";
  // The same counters as the statistics of the event stream and `vrflow monitor`.
  const nlohmann::json modules = statsSnapshot()["modules"];
  lastDisplayIterations_.resize(modules.size(), 0);
  for (std::size_t i = 0; i < modules.size(); ++i) {
    const uint64_t it = modules[i]["iterations"].get<uint64_t>();
    const double rate = dt > 0 ? static_cast<double>(it - lastDisplayIterations_[i]) / dt : 0.0;
    lastDisplayIterations_[i] = it;
    char text[128];
    std::snprintf(text, sizeof text, "  %s %.0f it/s", modules[i]["id"].get<std::string>().c_str(),
                  rate);
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

}  // namespace vrflow::run::detail
