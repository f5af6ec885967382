#include <dirent.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "vrflow/launcher/launch.hpp"

namespace vrflow::launcher {
namespace {

using nlohmann::json;

double rate(const json& now, const json& before, const char* key, double seconds) {
  if (before.is_null() || seconds <= 0 || !now.contains(key) || !before.contains(key)) return 0.0;
  return static_cast<double>(now[key].get<uint64_t>() - std::min(now[key].get<uint64_t>(),
                                                                  before[key].get<uint64_t>())) /
         seconds;
}

const json* findById(const json& list, const char* key, const std::string& value) {
  for (const auto& item : list) {
    if (item.value(key, "") == value) return &item;
  }
  return nullptr;
}

std::string render(const json& launch) {
  std::ostringstream out;
  char line[256];
  out << launch.value("application", "?") << "  (" << launch.value("file", "")
      << ", launcher pid " << launch.value("launcher_pid", 0) << ")\n";
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
    const double dt = before.is_null() ? 0.0
                                       : static_cast<double>(now["t_ns"].get<int64_t>() -
                                                             before["t_ns"].get<int64_t>()) / 1e9;
    for (const auto& m : now["modules"]) {
      const json* b = before.is_null() ? nullptr : findById(before["modules"], "id", m["id"]);
      const json prev = b ? *b : json();
      const double wait = rate(m, prev, "wait_ns", 1), compute = rate(m, prev, "compute_ns", 1);
      std::snprintf(line, sizeof line, "%-8s %-16s %10.1f %6.0f %-16s %6.0f %10.1f\n",
                    host.value("host", "?").c_str(), m.value("id", "?").c_str(),
                    rate(m, prev, "iterations", dt),
                    wait + compute > 0 ? 100.0 * wait / (wait + compute) : 0.0,
                    m.value("state", "?").c_str(), dt > 0 ? 100.0 * rate(m, prev, "cpu_ns", dt) / 1e9 : 0.0,
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
    const json& beforeLinks = !before.is_null() && before.contains("links") ? before["links"] : noLinks;
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
      std::snprintf(line, sizeof line, "  %-8s -> %-8s %10.1f msg/s out %10.3f MiB/s out %10.1f msg/s in %10.3f MiB/s in\n",
                    host.value("host", "?").c_str(), peerName.c_str(),
                    rate(l, prev, "messages_sent", dt), rate(l, prev, "bytes_sent", dt) / 1048576.0,
                    rate(l, prev, "messages_received", dt),
                    rate(l, prev, "bytes_received", dt) / 1048576.0);
      links << line;
    }
  }
  std::snprintf(line, sizeof line, "%-46s %11s %10s %10s\n", "CONNECTION", "QUEUE", "MSG/S", "MIB/S");
  out << line << connections.str();
  if (!links.str().empty()) out << "LINKS\n" << links.str();
  return out.str();
}

// The live launches: their monitor files whose launcher is still running.
std::vector<json> liveLaunches() {
  std::vector<json> launches;
  const std::string dir = monitorDirectory();
  DIR* d = opendir(dir.c_str());
  if (d == nullptr) return launches;
  while (dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name.rfind("monitor-", 0) != 0 || name.size() < 14 ||
        name.compare(name.size() - 5, 5, ".json") != 0) {
      continue;
    }
    const pid_t pid = std::atoi(name.c_str() + 8);
    if (pid <= 0 || kill(pid, 0) != 0) continue;
    std::ifstream in(dir + "/" + name);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto j = json::parse(text, nullptr, false);
    if (!j.is_discarded() && j.is_object() && j.contains("hosts")) launches.push_back(std::move(j));
  }
  closedir(d);
  return launches;
}

}  // namespace

std::string monitorDirectory() {
  std::string dir;
  if (const char* runtime = std::getenv("XDG_RUNTIME_DIR"); runtime != nullptr && *runtime != '\0') {
    dir = std::string(runtime) + "/vrflow";
  } else {
    dir = "/tmp/vrflow-" + std::to_string(getuid());
  }
  mkdir(dir.c_str(), 0700);
  return dir;
}

int monitor(bool once, bool asJson) {
  bool seen = false;
  while (true) {
    const auto launches = liveLaunches();
    if (launches.empty()) {
      if (!seen) std::fprintf(stderr, "vrflow monitor: no launch is running (looked in %s)\n",
                              monitorDirectory().c_str());
      return seen ? 0 : 1;
    }
    seen = true;
    std::string text;
    for (const auto& l : launches) text += asJson ? l.dump() + "\n" : render(l) + "\n";
    if (!once && !asJson && isatty(STDOUT_FILENO)) std::fputs("\033[H\033[2J", stdout);
    std::fputs(text.c_str(), stdout);
    std::fflush(stdout);
    if (once) return 0;
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
}

}  // namespace vrflow::launcher
