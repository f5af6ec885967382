// `vrflow monitor --events FILE|-`: the same table as for a running launch, from an event
// stream (docs/events.md) that `vrflow run --events` or `vrflow launch --events` writes.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "monitor_files.hpp"
#include "vrflow/launcher/launch.hpp"

namespace vrflow::launcher {
namespace {

using nlohmann::json;

// The launch as renderLaunch() wants it, kept up to date from the stream's events.
class StreamState {
 public:
  /// Takes one event; true when the table changed (a new statistics snapshot).
  bool take(const json& event) {
    const std::string kind = event.value("event", "");
    if (kind == "started") {
      launch_["application"] = event.value("application", "?");
      launch_["file"] = event.value("file", "");
      launch_["hosts"] = json::array();
      for (const auto& h : event.value("hosts", json::array())) {
        launch_["hosts"].push_back(
            {{"host", h.value("id", "?")}, {"now", nullptr}, {"before", nullptr}});
      }
      return false;
    }
    if (kind == "stats") {
      // `vrflow run` has one snapshot for all its hosts, without "host".
      json& host = hostEntry(event.value("host", ""));
      host["before"] = std::move(host["now"]);
      host["now"] = event;
      return true;
    }
    if (kind == "end") {
      ended_ = true;
      endLine_ = "run ended: " + event.value("status", "?") + " (exit " +
                 std::to_string(event.value("exit_code", -1)) + ")";
      const std::string error = event.value("error", "");
      if (!error.empty()) endLine_ += ": " + error;
    }
    return false;
  }
  const json& launch() const { return launch_; }
  bool ended() const { return ended_; }
  const std::string& endLine() const { return endLine_; }

 private:
  json& hostEntry(const std::string& id) {
    if (!launch_.contains("hosts")) launch_["hosts"] = json::array();
    json& hosts = launch_["hosts"];
    for (auto& h : hosts) {
      if (id.empty() || h["host"] == id) {
        if (id.empty() && hosts.size() > 1) h["host"] = "all";
        return h;
      }
    }
    hosts.push_back({{"host", id.empty() ? "all" : id}, {"now", nullptr}, {"before", nullptr}});
    return hosts.back();
  }

  json launch_ = {{"application", "?"}, {"file", ""}, {"hosts", json::array()}};
  bool ended_ = false;
  std::string endLine_;
};

}  // namespace

int monitorEvents(const std::string& source, bool once, bool asJson) {
  std::ifstream file;
  if (source != "-") {
    file.open(source);
    if (!file) {
      std::fprintf(stderr, "vrflow monitor: cannot read the events '%s'\n", source.c_str());
      return 1;
    }
  }
  std::istream& in = source == "-" ? std::cin : file;
  StreamState state;
  std::string line;
  while (!state.ended()) {
    if (!std::getline(in, line)) {
      // A file still being written: wait for more (standard input ends at its end).
      if (once || source == "-") break;
      in.clear();
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      continue;
    }
    const json event = json::parse(line, nullptr, /*allow_exceptions=*/false);
    if (!event.is_object()) continue;  // a line cut short, or not an event: skipped
    if (!state.take(event) || once) continue;
    if (asJson) {
      std::fputs((state.launch().dump() + "\n").c_str(), stdout);
    } else {
      if (isatty(STDOUT_FILENO)) std::fputs("\033[H\033[2J", stdout);
      std::fputs((renderLaunch(state.launch()) + "\n").c_str(), stdout);
    }
    std::fflush(stdout);
  }
  if (once) {
    std::fputs(((asJson ? state.launch().dump() : renderLaunch(state.launch())) + "\n").c_str(),
               stdout);
  }
  if (state.ended()) std::printf("%s\n", state.endLine().c_str());
  std::fflush(stdout);
  return 0;
}

}  // namespace vrflow::launcher
