#include "vrflow/run/trace.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "vrflow/base/version.hpp"
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
  auto merges = nlohmann::json::array();
  for (const auto& m : trace.merges) {
    merges.push_back({m.mergedSourceHash, m.mergedIteration, m.partSourceHash, m.partIteration});
  }
  j["merges"] = std::move(merges);
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
    if (j.contains("merges")) {
      for (const auto& m : j.at("merges")) {
        trace.merges.push_back({m.at(0).get<uint32_t>(), m.at(2).get<uint32_t>(),
                                m.at(1).get<uint64_t>(), m.at(3).get<uint64_t>()});
      }
    }
    return trace;
  } catch (const nlohmann::json::exception& e) {
    return makeError(std::string("malformed host trace: ") + e.what());
  }
}

namespace {

// How a filter on the way renumbers the messages it passes (docs/filters.md): `repeat` sends
// message i as i*count .. i*count+count-1; `decimate` (restamp on, its default) sends the last
// of group g (messages g*count .. g*count+count-1) as g. Other filters keep the iteration stamp.
struct Renumbering {
  enum class Kind { Repeat, Decimate } kind;
  uint64_t count;
  /// The iteration the message had before the filter, from the one it has after it.
  uint64_t before(uint64_t after) const {
    return kind == Kind::Repeat ? after / count : after * count + count - 1;
  }
};

std::optional<Renumbering> renumberingOf(const app::Filter& filter) {
  const auto value = [&](const std::string& name, const std::string& fallback) {
    for (const auto& p : filter.params)
      if (p.name == name) return p.value;
    return fallback;
  };
  const bool repeat = filter.type == "repeat";
  if (!repeat && !(filter.type == "decimate" && value("restamp", "true") == "true")) {
    return std::nullopt;
  }
  uint64_t count = 10;  // both filters' default
  try {
    count = std::stoull(value("count", "10"));
  } catch (const std::exception&) {
    return std::nullopt;  // validation refused such a file before it ran
  }
  if (count <= 1) return std::nullopt;
  return Renumbering{repeat ? Renumbering::Kind::Repeat : Renumbering::Kind::Decimate, count};
}

// Per module: the modules whose outputs reach it through filters only, each with the
// renumberings on the way, from the receiver upwards (the first path found when there are
// several).
using Feeders = std::map<std::string, std::vector<Renumbering>>;
std::map<std::string, Feeders> modulesFeeding(const app::Application& application) {
  std::set<std::string> modules;
  for (const auto& m : application.modules) modules.insert(m.id);
  std::map<std::string, std::optional<Renumbering>> filters;
  for (const auto& f : application.filters) filters[f.id] = renumberingOf(f);
  std::map<std::string, std::vector<std::string>> into;  // node -> nodes connected to its inputs
  for (const auto& c : application.connections) into[c.to.node].push_back(c.from.node);
  std::map<std::string, Feeders> feeding;
  for (const auto& m : application.modules) {
    auto& found = feeding[m.id];
    std::set<std::string> seen;
    std::vector<std::pair<std::string, std::vector<Renumbering>>> pending{{m.id, {}}};
    while (!pending.empty()) {
      const auto [node, way] = std::move(pending.back());
      pending.pop_back();
      for (const auto& from : into[node]) {
        if (modules.count(from) != 0) {
          found.emplace(from, way);
        } else if (seen.insert(from).second) {
          auto further = way;  // a filter: look further up
          if (const auto renumbering = filters[from]) further.push_back(*renumbering);
          pending.emplace_back(from, std::move(further));
        }
      }
    }
  }
  return feeding;
}

}  // namespace

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
  for (std::size_t i = 0; i < application.hosts.size(); ++i) {
    const app::Host& host = application.hosts[i];
    events.push_back({{"ph", "M"},
                      {"name", "process_name"},
                      {"pid", static_cast<int>(i) + 1},
                      {"args", {{"name", "host " + host.id + " (" + host.address + ")"}}}});
  }
  // Every put of a message, by the message's stamps (source, iteration): its sender's own put,
  // then each module that forwarded it unchanged.
  struct Put {
    std::string module;
    int pid, tid;
    double ts;
  };
  std::map<std::pair<uint32_t, uint64_t>, std::vector<Put>> puts;
  // The parts of each merged message, by the merged message's stamps.
  std::map<std::pair<uint32_t, uint64_t>, std::vector<std::pair<uint32_t, uint64_t>>> parts;
  for (const auto& h : hosts) {
    dropped += h.dropped;
    for (const auto& m : h.modules) {
      events.push_back({{"ph", "M"},
                        {"name", "thread_name"},
                        {"pid", pidOf(m)},
                        {"tid", moduleIndex(m) + 1},
                        {"args", {{"name", m}}}});
    }
    for (const auto& e : h.events) {
      if (e.event.kind != static_cast<uint32_t>(ipc::TraceKind::Sent)) continue;
      const std::string& m = h.modules[e.module];
      puts[{e.event.sourceHash, e.event.sourceIteration}].push_back(
          Put{m, pidOf(m), moduleIndex(m) + 1, us(h, e.event.beginNs)});
    }
    for (const auto& m : h.merges) {
      auto& list = parts[{m.mergedSourceHash, m.mergedIteration}];
      const std::pair<uint32_t, uint64_t> part{m.partSourceHash, m.partIteration};
      if (std::find(list.begin(), list.end(), part) == list.end()) list.push_back(part);
    }
  }
  const auto feeders = modulesFeeding(application);
  // The put that delivered a message to `receiver` at `ts`: among the modules that put it and
  // feed the receiver (through filters only), the last hop; its first put not after `ts`.
  auto deliveringPut = [&](const std::vector<Put>& candidates, const std::string& receiver,
                           double ts) -> const Put* {
    // A module the application does not connect (none known) takes any sender.
    const auto fed = feeders.find(receiver);
    const bool known = fed != feeders.end() && !fed->second.empty();
    std::map<std::string, const Put*> firstOfModule;
    const Put* earliest = nullptr;  // across hosts, clocks are aligned only so well
    for (const auto& p : candidates) {
      if (known && !fed->second.contains(p.module)) continue;
      if (earliest == nullptr || p.ts < earliest->ts) earliest = &p;
      if (p.ts > ts) continue;
      auto& first = firstOfModule[p.module];
      if (first == nullptr || p.ts < first->ts) first = &p;
    }
    const Put* best = nullptr;
    for (const auto& [module, p] : firstOfModule) {
      if (best == nullptr || p->ts > best->ts) best = p;
    }
    return best != nullptr ? best : earliest;
  };
  uint64_t flowId = 0;
  for (const auto& h : hosts) {
    for (const auto& e : h.events) {
      const std::string& receiver = h.modules[e.module];
      const int pid = pidOf(receiver);
      const int tid = moduleIndex(receiver) + 1;
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
        const std::pair<uint32_t, uint64_t> received{e.event.sourceHash, e.event.sourceIteration};
        const auto merged = parts.find(received);
        const std::vector<std::pair<uint32_t, uint64_t>> messages =
            merged != parts.end() ? merged->second : std::vector{received};
        const double ts = us(h, e.event.endNs);
        // A message renumbered on its way (repeat, decimate) is its sender's message of the
        // iteration it had before; the sender is the feeder whose id hashes to its source.
        const auto fed = feeders.find(receiver);
        const auto original = [&](std::pair<uint32_t, uint64_t> message) {
          if (fed == feeders.end()) return message;
          for (const auto& [feeder, way] : fed->second) {
            if (way.empty() || msg::fnv1a32(feeder) != message.first) continue;
            for (const auto& renumbering : way) message.second = renumbering.before(message.second);
            break;
          }
          return message;
        };
        for (const auto& part : messages) {
          const auto put = puts.find(original(part));
          if (put == puts.end()) continue;  // an initial message, or one a filter made
          const Put* from = deliveringPut(put->second, receiver, ts);
          if (from == nullptr) continue;
          ++flowId;
          const std::string name = from->module + " -> " + receiver;
          events.push_back({{"ph", "s"},
                            {"name", name},
                            {"cat", "message"},
                            {"id", flowId},
                            {"pid", from->pid},
                            {"tid", from->tid},
                            {"ts", from->ts}});
          events.push_back({{"ph", "f"},
                            {"bp", "e"},
                            {"name", name},
                            {"cat", "message"},
                            {"id", flowId},
                            {"pid", pid},
                            {"tid", tid},
                            {"ts", ts}});
        }
      }
    }
  }
  json trace;
  trace["traceEvents"] = std::move(events);
  trace["displayTimeUnit"] = "ms";
  trace["otherData"] = {{"application", application.name},
                        {"vrflow_version", versionText()},
                        {"dropped_events", dropped}};
  return trace.dump();
}

}  // namespace vrflow::run
