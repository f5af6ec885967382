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

#include "monitor_table.hpp"
#include "vrflow/launcher/launch.hpp"
#include "vrflow/run/run_state.hpp"

namespace vrflow::launcher {
using nlohmann::json;

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
  run::RunState state;
  std::string line;
  while (!state.ended()) {
    if (!std::getline(in, line)) {
      // A file still being written: wait for more (standard input ends at its end).
      if (once || source == "-") break;
      in.clear();
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      continue;
    }
    // A line cut short, or not an event, is skipped.
    if (!state.take(line) || once) continue;
    if (asJson) {
      std::fputs((state.toJson() + "\n").c_str(), stdout);
    } else {
      if (isatty(STDOUT_FILENO)) std::fputs("\033[H\033[2J", stdout);
      std::fputs((renderLaunch(json::parse(state.toJson())) + "\n").c_str(), stdout);
    }
    std::fflush(stdout);
  }
  if (once) {
    std::fputs(
        ((asJson ? state.toJson() : renderLaunch(json::parse(state.toJson()))) + "\n").c_str(),
        stdout);
  }
  if (state.ended()) std::printf("%s\n", state.endLine().c_str());
  std::fflush(stdout);
  return 0;
}

}  // namespace vrflow::launcher
