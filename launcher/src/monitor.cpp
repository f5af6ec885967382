// `vrflow monitor [RUN]`: the live statistics of a registered run (docs/operations.md).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "monitor_table.hpp"
#include "vrflow/launcher/launch.hpp"
#include "vrflow/run/registry.hpp"

namespace vrflow::launcher {
namespace {

using nlohmann::json;

double rate(const json& now, const json& before, const char* key, double seconds) {
  if (before.is_null() || seconds <= 0 || !now.contains(key) || !before.contains(key)) return 0.0;
  return static_cast<double>(now[key].get<uint64_t>() -
                             std::min(now[key].get<uint64_t>(), before[key].get<uint64_t>())) /
         seconds;
}

const json* findById(const json& list, const char* key, const std::string& value) {
  for (const auto& item : list) {
    if (item.value(key, "") == value) return &item;
  }
  return nullptr;
}

}  // namespace

std::string renderLaunch(const json& launch) {
  std::ostringstream out;
  char line[256];
  out << launch.value("application", "?") << "  (" << launch.value("file", "");
  if (launch.contains("launcher_pid")) out << ", launcher pid " << launch.value("launcher_pid", 0);
  if (launch.contains("pid")) out << ", pid " << launch.value("pid", 0);
  out << ")\n";
  std::snprintf(line, sizeof line, "%-8s %-16s %10s %6s %-16s %6s %10s\n", "HOST", "MODULE", "IT/S",
                "WAIT%", "STATE", "CPU%", "RSS MiB");
  out << line;
  std::ostringstream connections, links;
  for (const auto& host : launch["hosts"]) {
    const json& now = host["now"];
    const json& before = host["before"];
    if (now.is_null()) {
      std::snprintf(line, sizeof line, "%-8s (starting)\n", host.value("host", "?").c_str());
      out << line;
      continue;
    }
    const double dt =
        before.is_null()
            ? 0.0
            : static_cast<double>(now["t_ns"].get<int64_t>() - before["t_ns"].get<int64_t>()) / 1e9;
    for (const auto& m : now["modules"]) {
      const json* b = before.is_null() ? nullptr : findById(before["modules"], "id", m["id"]);
      const json prev = b ? *b : json();
      const double wait = rate(m, prev, "wait_ns", 1), compute = rate(m, prev, "compute_ns", 1);
      std::snprintf(line, sizeof line, "%-8s %-16s %10.1f %6.0f %-16s %6.0f %10.1f\n",
                    host.value("host", "?").c_str(), m.value("id", "?").c_str(),
                    rate(m, prev, "iterations", dt),
                    wait + compute > 0 ? 100.0 * wait / (wait + compute) : 0.0,
                    m.value("state", "?").c_str(),
                    dt > 0 ? 100.0 * rate(m, prev, "cpu_ns", dt) / 1e9 : 0.0,
                    static_cast<double>(m.value("rss_bytes", uint64_t{0})) / 1048576.0);
      out << line;
    }
    for (const auto& c : now["connections"]) {
      const json* b = nullptr;
      if (!before.is_null()) {
        for (const auto& item : before["connections"]) {
          if (item["from"] == c["from"] && item["to"] == c["to"]) b = &item;
        }
      }
      const json prev = b ? *b : json();
      std::snprintf(line, sizeof line, "  %-44s %5zu/%-5zu %10.1f %10.3f\n",
                    (c.value("from", "") + " -> " + c.value("to", "")).c_str(),
                    c.value("length", std::size_t{0}), c.value("capacity", std::size_t{0}),
                    rate(c, prev, "messages", dt), rate(c, prev, "bytes", dt) / 1048576.0);
      connections << line;
    }
    const json noLinks = json::array();
    const json& nowLinks = now.contains("links") ? now["links"] : noLinks;
    const json& beforeLinks =
        !before.is_null() && before.contains("links") ? before["links"] : noLinks;
    for (const auto& l : nowLinks) {
      const json* b = nullptr;
      for (const auto& item : beforeLinks) {
        if (item["peer"] == l["peer"]) b = &item;
      }
      const json prev = b ? *b : json();
      const int peer = l.value("peer", -1);
      std::string peerName = "#" + std::to_string(peer);
      if (peer >= 0 && static_cast<std::size_t>(peer) < launch["hosts"].size()) {
        peerName = launch["hosts"][static_cast<std::size_t>(peer)].value("host", peerName);
      }
      std::snprintf(
          line, sizeof line,
          "  %-8s -> %-8s %10.1f msg/s out %10.3f MiB/s out %10.1f msg/s in %10.3f MiB/s in\n",
          host.value("host", "?").c_str(), peerName.c_str(), rate(l, prev, "messages_sent", dt),
          rate(l, prev, "bytes_sent", dt) / 1048576.0, rate(l, prev, "messages_received", dt),
          rate(l, prev, "bytes_received", dt) / 1048576.0);
      links << line;
    }
  }
  std::snprintf(line, sizeof line, "%-46s %11s %10s %10s\n", "CONNECTION", "QUEUE", "MSG/S",
                "MIB/S");
  out << line << connections.str();
  if (!links.str().empty()) out << "LINKS\n" << links.str();
  return out.str();
}

int monitor(const std::string& runPrefix, bool once, bool asJson) {
  auto found = run::findRun(runPrefix, /*all=*/true);
  if (!found) {
    std::fprintf(stderr, "vrflow monitor: %s\n", found.error().message.c_str());
    return 1;
  }
  const std::string id = found->identity.id;
  if (!found->running) {
    std::fprintf(stderr,
                 "vrflow monitor: run '%s' has ended (%s); `vrflow logs %s` shows its logs\n",
                 id.c_str(), found->stateWord().c_str(), id.c_str());
    return 1;
  }
  while (true) {
    // The record moves to the state folder when the run ends: found again by its whole id.
    auto record = run::findRun(id, /*all=*/true);
    if (!record) {
      std::fprintf(stderr, "vrflow monitor: %s\n", record.error().message.c_str());
      return 1;
    }
    json shown = json::parse(record->state.toJson());
    shown[record->identity.kind == "launch" ? "launcher_pid" : "pid"] = record->identity.pid;
    if (!once && !asJson && isatty(STDOUT_FILENO)) std::fputs("\033[H\033[2J", stdout);
    std::fputs(((asJson ? shown.dump() : renderLaunch(shown)) + "\n").c_str(), stdout);
    if (!record->running) std::printf("%s\n", record->state.endLine().c_str());
    std::fflush(stdout);
    if (once || !record->running) return 0;
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
}

int followEvents(const std::string& runPrefix) {
  auto found = run::findRun(runPrefix, /*all=*/true);
  if (!found) {
    std::fprintf(stderr, "vrflow monitor: %s\n", found.error().message.c_str());
    return 1;
  }
  const run::RunIdentity identity = found->identity;
  if (!found->running) {
    std::fprintf(stderr,
                 "vrflow monitor: run '%s' has ended (%s); `vrflow logs %s` shows its logs\n",
                 identity.id.c_str(), found->stateWord().c_str(), identity.id.c_str());
    return 1;
  }
  auto print = [](const json& event) {
    std::fputs((event.dump() + "\n").c_str(), stdout);
    std::fflush(stdout);
  };
  // The registration knows the hosts and module ids, not their types or placement.
  json started = {
      {"event", "started"},      {"time", 0.0},        {"application", identity.application},
      {"file", identity.file},   {"run", identity.id}, {"hosts", json::array()},
      {"modules", json::array()}};
  for (const auto& host : identity.hosts) started["hosts"].push_back({{"id", host}});
  for (const auto& module : identity.modules) started["modules"].push_back({{"id", module}});
  print(started);
  double time = 0;
  std::map<std::string, int64_t> printedStats;  // host -> t_ns of the last stats printed
  json printedWarnings = json::array();
  while (true) {
    // The record moves to the state folder when the run ends: found again by its whole id.
    auto record = run::findRun(identity.id, /*all=*/true);
    if (!record) {
      std::fprintf(stderr, "vrflow monitor: %s\n", record.error().message.c_str());
      return 1;
    }
    const json state = json::parse(record->state.toJson());
    for (const auto& host : state["hosts"]) {
      const json& now = host["now"];
      if (!now.is_object()) continue;
      const std::string name = host.value("host", "");
      const int64_t at = now.value("t_ns", int64_t{0});
      const bool seen = printedStats.count(name) != 0;
      if (seen && printedStats[name] == at) continue;
      printedStats[name] = at;
      // A host seen for the first time: its previous snapshot too, so that rates follow at once.
      for (const json* snapshot : {seen ? nullptr : &host["before"], &now}) {
        if (snapshot == nullptr || !snapshot->is_object()) continue;
        json stats = *snapshot;
        time = std::max(time, stats.value("time", 0.0));
        stats["time"] = time;
        if (identity.kind == "launch" && !stats.contains("host")) stats["host"] = name;
        print(stats);
      }
    }
    // The warnings kept are the last ones: the new ones follow the overlap with those printed.
    const json& warnings = state["warnings"];
    std::size_t overlap = std::min(printedWarnings.size(), warnings.size());
    while (overlap > 0 &&
           !std::equal(warnings.begin(), warnings.begin() + static_cast<std::ptrdiff_t>(overlap),
                       printedWarnings.end() - static_cast<std::ptrdiff_t>(overlap))) {
      --overlap;
    }
    for (std::size_t i = overlap; i < warnings.size(); ++i) {
      print({{"event", "warning"}, {"time", time}, {"text", warnings[i]}});
    }
    printedWarnings = warnings;
    if (!record->running) {
      const json end = state["end"].is_object() ? state["end"] : json::object();
      print({{"event", "end"},
             {"time", time},
             {"exit_code", end.value("exit_code", -1)},
             {"status", end.value("status", "lost")},
             {"error", end.value("error", "")}});
      return 0;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

}  // namespace vrflow::launcher
