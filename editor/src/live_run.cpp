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

// The host a line names after `prefix` ("host 'b'"), or empty.
std::string hostNamedIn(const std::string& line, const std::string& prefix = "host '") {
  const auto at = line.find(prefix);
  if (at == std::string::npos) return {};
  const auto end = line.find('\'', at + prefix.size());
  return end == std::string::npos ? std::string()
                                  : line.substr(at + prefix.size(), end - at - prefix.size());
}

// The host a line says was lost: the peer of "lost the link to host 'c'" (what a daemon says
// of a peer gone silent), or the host whose daemon died; empty when none.
std::string lostHostIn(const std::string& line) {
  const std::string peer = hostNamedIn(line, "lost the link to host '");
  if (!peer.empty()) return peer;
  if (line.find("closed its control channel") != std::string::npos ||
      line.find("lost") != std::string::npos)
    return hostNamedIn(line);
  return {};
}

// The entry of `list` from `from` to `to`, added when there is none.
template <typename T>
T& entryOf(std::vector<T>& list, const std::string& from, const std::string& to) {
  for (auto& x : list) {
    if (x.from == from && x.to == to) return x;
  }
  T& added = list.emplace_back();
  added.from = from;
  added.to = to;
  return added;
}

}  // namespace

HostLive* LiveRun::host(const std::string& id) {
  for (auto& h : hosts) {
    if (h.id == id) return &h;
  }
  return nullptr;
}

const HostLive* LiveRun::host(const std::string& id) const {
  return const_cast<LiveRun*>(this)->host(id);
}

const ConnectionLive* LiveRun::connection(const std::string& from, const std::string& to) const {
  for (const auto& c : connections) {
    if (c.from == from && c.to == to) return &c;
  }
  return nullptr;
}

const LinkLive* LiveRun::link(const std::string& from, const std::string& to) const {
  for (const auto& l : links) {
    if (l.from == from && l.to == to) return &l;
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
  previousTraffic_.clear();
  badLines_ = 0;
}

void LiveRunModel::readStats(const json& event) {
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
      // An ended process uses no CPU; its last interval's figure would stay forever.
      if (module.state == "ended" || module.state == "finished") module.cpu = 0;
      if (dt > 0) {
        module.history.push_back(module.rate);
        while (module.history.size() > keep) module.history.pop_front();
      }
    }
  }
  readConnections(event);
  readLinks(event, statsHost);
  sumHosts();
}

void LiveRunModel::readConnections(const json& event) {
  if (!event.contains("connections") || !event["connections"].is_array()) return;
  for (const auto& c : event["connections"]) {
    if (!c.is_object()) continue;
    const std::string from = text(c, "from"), to = text(c, "to");
    ConnectionLive& connection = entryOf(run_.connections, from, to);
    connection.length = count(c, "length");
    connection.capacity = count(c, "capacity");
    connection.fill = connection.capacity > 0
                          ? std::min(1.0, static_cast<double>(connection.length) /
                                              static_cast<double>(connection.capacity))
                          : 0;
    connection.messages = count(c, "messages");
    connection.bytes = count(c, "bytes");
    connection.dropped = count(c, "dropped");
    traffic("c\n" + from + "\n" + to, connection);
  }
}

void LiveRunModel::readLinks(const json& event, const std::string& host) {
  if (host.empty() || !event.contains("links") || !event["links"].is_array()) return;
  for (const auto& l : event["links"]) {
    if (!l.is_object() || !l.contains("peer") || !l["peer"].is_number_integer()) continue;
    const int peer = l["peer"].get<int>();
    if (peer < 0 || static_cast<std::size_t>(peer) >= run_.hosts.size()) continue;
    const std::string to = run_.hosts[static_cast<std::size_t>(peer)].id;
    LinkLive& link = entryOf(run_.links, host, to);
    link.messages = count(l, "messages_sent");
    link.bytes = count(l, "bytes_sent");
    traffic("l\n" + host + "\n" + to, link);
  }
}

template <typename T>
void LiveRunModel::traffic(const std::string& key, T& counted) {
  Counters& was = previousTraffic_[key];
  const double dt = was.time >= 0 ? run_.time - was.time : 0;
  if (dt > 0) {
    counted.messagesPerSecond =
        static_cast<double>(counted.messages - std::min(counted.messages, was.messages)) / dt;
    counted.mibPerSecond =
        static_cast<double>(counted.bytes - std::min(counted.bytes, was.bytes)) / dt / 1048576.0;
  }
  was = Counters{run_.time, counted.messages, counted.bytes};
}

void LiveRunModel::markHost(const std::string& host, const std::string& cause, bool lost) {
  HostLive* h = run_.host(host);
  if (h == nullptr) {
    run_.hosts.emplace_back().id = host;
    h = &run_.hosts.back();
  }
  if (h->cause.empty()) h->cause = cause;
  h->lost = h->lost || lost;
}

void LiveRunModel::sumHosts() {
  for (auto& h : run_.hosts) {
    h.cpu = 0;
    h.rssMiB = 0;
    h.modules = 0;
  }
  for (const auto& [id, module] : run_.modules) {
    HostLive* h = run_.host(module.host);
    if (h == nullptr) continue;
    h->cpu += module.cpu;
    h->rssMiB += module.rssMiB;
    ++h->modules;
  }
}

void LiveRunModel::handleLine(const QByteArray& line) {
  const json event = json::parse(line.constData(), line.constData() + line.size(), nullptr, false);
  if (!event.is_object() || !event.contains("event") || !event["event"].is_string()) {
    ++badLines_;
    return;
  }
  const std::string kind = event["event"].get<std::string>();
  if (kind == "started" && run_.phase == LiveRun::Phase::Ended) reset();  // the next run
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
    readStats(event);
  } else if (kind == "warning") {
    run_.warnings.push_back(text(event, "text"));
    const std::string lost = lostHostIn(run_.warnings.back());
    if (!lost.empty()) markHost(lost, run_.warnings.back(), true);
  } else if (kind == "module_exit") {
    auto& module = run_.modules[text(event, "module")];
    if (module.id.empty()) module.id = text(event, "module");
    if (module.host.empty()) module.host = text(event, "host");
    module.state = "exited";
    module.exit = text(event, "exit");
    const std::string cause = text(event, "cause");
    if (!cause.empty()) module.failure = cause;
    sumHosts();
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
      const std::string lost = lostHostIn(run_.error);
      if (!lost.empty()) {
        markHost(lost, run_.error, true);
      } else if (const std::string host = hostNamedIn(run_.error); !host.empty()) {
        markHost(host, run_.error, false);
      }
    }
    sumHosts();
    Q_EMIT changed();
    Q_EMIT ended();
    return;
  } else {
    return;  // a kind this editor does not know: later versions may add some
  }
  Q_EMIT changed();
}

}  // namespace vrflow::editor::gui
