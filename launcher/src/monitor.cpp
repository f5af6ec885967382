#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "monitor_files.hpp"
#include "vrflow/launcher/launch.hpp"
#include "vrflow/run/run_folders.hpp"

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

namespace {

// A monitor file larger than this is not a launcher's (they hold a few KiB per host).
constexpr off_t kMaxMonitorFileBytes = off_t{16} << 20;

// The launcher pid in a monitor file's name ("monitor-PID.json", or a temporary
// "monitor-PID.json.XXXXXX" of publishMonitorFile()), or 0 if the name is not one.
pid_t launcherOf(const std::string& name, bool& temporary) {
  if (name.rfind("monitor-", 0) != 0) return 0;
  char* end = nullptr;
  const long pid = std::strtol(name.c_str() + 8, &end, 10);
  if (pid <= 0 || end == name.c_str() + 8 || std::strncmp(end, ".json", 5) != 0) return 0;
  temporary = end[5] != '\0';
  if (temporary && end[5] != '.') return 0;
  return static_cast<pid_t>(pid);
}

bool processGone(pid_t pid) {
  return kill(pid, 0) != 0 && errno == ESRCH;
}

// A regular file of `dir` (never through a symbolic link), at most kMaxMonitorFileBytes.
std::string readMonitorFile(int dir, const std::string& name) {
  const int fd = openat(dir, name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return {};
  struct stat info {};
  std::string text;
  if (fstat(fd, &info) == 0 && S_ISREG(info.st_mode) && info.st_size <= kMaxMonitorFileBytes) {
    text.resize(static_cast<std::size_t>(info.st_size));
    const ssize_t n = read(fd, text.data(), text.size());
    text.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
  }
  close(fd);
  return text;
}

// The live launches: their monitor files whose launcher is still running.
Result<std::vector<json>> liveLaunches() {
  auto dir = monitorDirectory();
  if (!dir) return dir.error();
  removeStaleMonitorFiles(*dir);
  std::vector<json> launches;
  DIR* d = opendir(dir->c_str());
  if (d == nullptr) return launches;
  while (dirent* e = readdir(d)) {
    bool temporary = false;
    const pid_t pid = launcherOf(e->d_name, temporary);
    if (pid <= 0 || temporary || kill(pid, 0) != 0) continue;
    auto j = json::parse(readMonitorFile(dirfd(d), e->d_name), nullptr, false);
    if (!j.is_discarded() && j.is_object() && j.contains("hosts")) launches.push_back(std::move(j));
  }
  closedir(d);
  return launches;
}

}  // namespace

Result<std::string> monitorDirectory() {
  return run::runtimeDirectory();
}

void removeStaleMonitorFiles(const std::string& dir) {
  DIR* d = opendir(dir.c_str());
  if (d == nullptr) return;
  while (dirent* e = readdir(d)) {
    bool temporary = false;
    const pid_t pid = launcherOf(e->d_name, temporary);
    if (pid > 0 && processGone(pid)) {
      unlinkat(dirfd(d), e->d_name, 0);
    }
  }
  closedir(d);
}

bool publishMonitorFile(const std::string& dir, const std::string& text) {
  const std::string path = dir + "/monitor-" + std::to_string(getpid()) + ".json";
  // mkostemp opens with O_CREAT | O_EXCL: a name that exists (a link planted there included)
  // is never opened, and rename() replaces a link at `path` instead of following it.
  std::string temp = path + ".XXXXXX";
  const int fd = mkostemp(temp.data(), O_CLOEXEC);
  if (fd < 0) return false;
  bool ok = fchmod(fd, 0600) == 0;
  for (std::size_t done = 0; ok && done < text.size();) {
    const ssize_t n = write(fd, text.data() + done, text.size() - done);
    ok = n > 0;
    if (ok) done += static_cast<std::size_t>(n);
  }
  ok = close(fd) == 0 && ok;
  if (ok && rename(temp.c_str(), path.c_str()) == 0) return true;
  unlink(temp.c_str());
  return false;
}

void removeMonitorFile(const std::string& dir) {
  unlink((dir + "/monitor-" + std::to_string(getpid()) + ".json").c_str());
}

int monitor(bool once, bool asJson) {
  bool seen = false;
  while (true) {
    const auto launches = liveLaunches();
    if (!launches) {
      std::fprintf(stderr, "vrflow monitor: %s\n", launches.error().message.c_str());
      return 1;
    }
    if (launches->empty()) {
      if (!seen)
        std::fprintf(stderr, "vrflow monitor: no launch is running (looked in %s)\n",
                     monitorDirectory()->c_str());
      return seen ? 0 : 1;
    }
    seen = true;
    std::string text;
    for (const auto& l : *launches) text += asJson ? l.dump() + "\n" : renderLaunch(l) + "\n";
    if (!once && !asJson && isatty(STDOUT_FILENO)) std::fputs("\033[H\033[2J", stdout);
    std::fputs(text.c_str(), stdout);
    std::fflush(stdout);
    if (once) return 0;
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
}

}  // namespace vrflow::launcher
