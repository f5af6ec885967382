// What a run shows while it runs: the progress line for people, the statistics for the
// launcher and the event stream, the modules' traces.
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

void Supervisor::showProgress(const RunOutcome* end) {
  if (end == nullptr ? !progress_.due() : options_.progress == ProgressMode::Off) return;
  // The modules' counters, as the statistics of the event stream and `vrflow monitor` show them.
  std::vector<ModuleProgress> modules;
  for (const auto& module : daemon_.modules()) {
    const ipc::ModuleSlotDaemon slot = daemon_.slot(module.slotIndex);
    modules.push_back({slot.iterations(), slot.iterationLimit()});
  }
  const uint64_t done = outerIterationsDone(modules, options_.iterations);
  if (end != nullptr) {
    progress_.finish(done, end->status);
  } else {
    progress_.update(done);
  }
}

}  // namespace vrflow::run::detail
