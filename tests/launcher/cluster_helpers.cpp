#include "cluster_helpers.hpp"

#include <sys/stat.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

// `text` with each NUL (the separator of /proc's cmdline and environ) replaced by `separator`.
std::string words(std::string text, char separator) {
  for (char& c : text) c = c == '\0' ? separator : c;
  return text;
}

DaemonSeen daemonNow(const std::string& appFile, const std::string& host,
                     const std::string& program) {
  for (const ProcessInfo& p : processTable()) {
    if (p.name != program) continue;
    const std::string proc = "/proc/" + std::to_string(p.pid);
    const std::string commandLine = words(readFile(proc + "/cmdline"), ' ');
    if (commandLine.find(appFile + " ") == std::string::npos) continue;
    if (!host.empty() && commandLine.find(" --host " + host + " ") == std::string::npos) continue;
    return {p.pid, commandLine, "\n" + words(readFile(proc + "/environ"), '\n')};
  }
  return {};
}

}  // namespace

DaemonSeen findDaemon(const std::string& appFile, const std::string& host,
                      const std::string& program) {
  for (int i = 0; i < 300; ++i) {
    if (DaemonSeen seen = daemonNow(appFile, host, program); seen.pid > 0) return seen;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return {};
}

void useOwnHome() {
  static const TempDir home;
  for (const auto& [variable, folder] :
       {std::pair{"HOME", "home"}, std::pair{"XDG_RUNTIME_DIR", "runtime"},
        std::pair{"XDG_STATE_HOME", "state"}}) {
    const std::string path = home.file(folder);
    mkdir(path.c_str(), 0700);
    setenv(variable, path.c_str(), 1);
  }
}

bool daemonOfFileRuns(const std::string& appFile) {
  return daemonNow(appFile, "", "vrflow-daemon").pid > 0;
}

nlohmann::json deterministicPart(const std::string& reportPath) {
  auto report = nlohmann::json::parse(readFile(reportPath));
  report.erase("timing");
  report.erase("file");
  for (auto& m : report["modules"]) {
    m.erase("timing");
    m.erase("host");
  }
  return report;
}

}  // namespace vrflow::testing
