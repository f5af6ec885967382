#include "vrflow/run/trace.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>

#include "vrflow/message/ids.hpp"

namespace vrflow::run {

void drainTraceRing(ipc::TraceRing& ring, uint32_t module, HostTrace& trace) {
  const uint64_t head = ring.head.load(std::memory_order_acquire);
  uint64_t tail = ring.tail.load(std::memory_order_relaxed);
  for (; tail < head; ++tail) {
    if (trace.events.size() >= kMaxTraceEventsPerHost) {
      ++trace.dropped;
      continue;
    }
    trace.events.push_back({module, ring.events[tail % ipc::kTraceCapacity]});
  }
  ring.tail.store(tail, std::memory_order_release);
}

std::string hostTraceToJson(const HostTrace& trace) {
  nlohmann::json j;
  j["host"] = trace.host;
  j["offset_ns"] = trace.clockOffsetNs;
  j["modules"] = trace.modules;
  j["dropped"] = trace.dropped;
  auto events = nlohmann::json::array();
  for (const auto& e : trace.events) {
    events.push_back({e.module, e.event.kind, e.event.beginNs, e.event.endNs, e.event.iteration,
                      e.event.sourceHash, e.event.sourceIteration});
  }
  j["events"] = std::move(events);
  return j.dump();
}

Result<HostTrace> hostTraceFromJson(const std::string& text) {
  auto j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return makeError("malformed host trace");
  try {
    HostTrace trace;
    trace.host = j.at("host").get<std::string>();
    trace.clockOffsetNs = j.at("offset_ns").get<int64_t>();
    trace.modules = j.at("modules").get<std::vector<std::string>>();
    trace.dropped = j.at("dropped").get<uint64_t>();
    for (const auto& e : j.at("events")) {
      HostTrace::Event event;
      event.module = e.at(0).get<uint32_t>();
      if (event.module >= trace.modules.size()) return makeError("malformed host trace");
      event.event.kind = e.at(1).get<uint32_t>();
      event.event.beginNs = e.at(2).get<uint64_t>();
      event.event.endNs = e.at(3).get<uint64_t>();
      event.event.iteration = e.at(4).get<uint64_t>();
      event.event.sourceHash = e.at(5).get<uint32_t>();
      event.event.sourceIteration = e.at(6).get<uint64_t>();
      trace.events.push_back(event);
    }
    return trace;
  } catch (const nlohmann::json::exception& e) {
    return makeError(std::string("malformed host trace: ") + e.what());
  }
}

std::string chromeTrace(const app::Application& application, const std::vector<HostTrace>& hosts) {
  using nlohmann::json;
  auto hostIndex = [&](const std::string& id) {
    for (std::size_t i = 0; i < application.hosts.size(); ++i) {
      if (application.hosts[i].id == id) return static_cast<int>(i);
    }
    return static_cast<int>(application.hosts.size());
  };
  // Each module is drawn under the host the file maps it to.
  auto pidOf = [&](const std::string& module) {
    for (const auto& m : application.modules) {
      if (m.id == module) return hostIndex(app::effectiveHost(application, m.host)) + 1;
    }
    return static_cast<int>(application.hosts.size()) + 1;
  };
  auto moduleIndex = [&](const std::string& id) {
    for (std::size_t i = 0; i < application.modules.size(); ++i) {
      if (application.modules[i].id == id) return static_cast<int>(i);
    }
    return static_cast<int>(application.modules.size());
  };
  std::map<uint32_t, std::string> byHash;
  for (const auto& m : application.modules) byHash[msg::fnv1a32(m.id)] = m.id;

  // The earliest aligned time is 0.
  int64_t base = std::numeric_limits<int64_t>::max();
  for (const auto& h : hosts) {
    for (const auto& e : h.events) {
      base = std::min(base, static_cast<int64_t>(e.event.beginNs) - h.clockOffsetNs);
    }
  }
  auto us = [&](const HostTrace& h, uint64_t ns) {
    return static_cast<double>(static_cast<int64_t>(ns) - h.clockOffsetNs - base) / 1000.0;
  };
  json events = json::array();
  uint64_t dropped = 0;
  // Where each module put each iteration's first message: flows start there.
  struct Put {
    int pid, tid;
    double ts;
  };
  std::map<std::pair<std::string, uint64_t>, Put> puts;
  for (std::size_t i = 0; i < application.hosts.size(); ++i) {
    const app::Host& host = application.hosts[i];
    events.push_back({{"ph", "M"}, {"name", "process_name"}, {"pid", static_cast<int>(i) + 1},
                      {"args", {{"name", "host " + host.id + " (" + host.address + ")"}}}});
  }
  for (const auto& h : hosts) {
    dropped += h.dropped;
    for (const auto& m : h.modules) {
      events.push_back({{"ph", "M"}, {"name", "thread_name"}, {"pid", pidOf(m)},
                        {"tid", moduleIndex(m) + 1}, {"args", {{"name", m}}}});
    }
    for (const auto& e : h.events) {
      if (e.event.kind != static_cast<uint32_t>(ipc::TraceKind::Sent)) continue;
      const std::string& m = h.modules[e.module];
      puts.emplace(std::make_pair(m, e.event.iteration),
                   Put{pidOf(m), moduleIndex(m) + 1, us(h, e.event.beginNs)});
    }
  }
  uint64_t flowId = 0;
  for (const auto& h : hosts) {
    for (const auto& e : h.events) {
      const int pid = pidOf(h.modules[e.module]);
      const int tid = moduleIndex(h.modules[e.module]) + 1;
      const auto kind = static_cast<ipc::TraceKind>(e.event.kind);
      if (kind == ipc::TraceKind::Wait || kind == ipc::TraceKind::Compute) {
        events.push_back({{"ph", "X"},
                          {"name", kind == ipc::TraceKind::Wait ? "wait" : "compute"},
                          {"cat", "module"},
                          {"pid", pid},
                          {"tid", tid},
                          {"ts", us(h, e.event.beginNs)},
                          {"dur", static_cast<double>(e.event.endNs - e.event.beginNs) / 1000.0},
                          {"args", {{"iteration", e.event.iteration}}}});
      } else if (kind == ipc::TraceKind::Received) {
        const auto source = byHash.find(e.event.sourceHash);
        if (source == byHash.end()) continue;  // an initial message: no sender
        const auto put = puts.find({source->second, e.event.sourceIteration});
        if (put == puts.end()) continue;
        ++flowId;
        const std::string name = source->second + " -> " + h.modules[e.module];
        events.push_back({{"ph", "s"}, {"name", name}, {"cat", "message"}, {"id", flowId},
                          {"pid", put->second.pid}, {"tid", put->second.tid}, {"ts", put->second.ts}});
        events.push_back({{"ph", "f"}, {"bp", "e"}, {"name", name}, {"cat", "message"},
                          {"id", flowId}, {"pid", pid}, {"tid", tid}, {"ts", us(h, e.event.endNs)}});
      }
    }
  }
  json trace;
  trace["traceEvents"] = std::move(events);
  trace["displayTimeUnit"] = "ms";
  trace["otherData"] = {{"application", application.name}, {"dropped_events", dropped}};
  return trace.dump();
}

}  // namespace vrflow::run
