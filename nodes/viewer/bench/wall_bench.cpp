// vrflow-bench-wall: the demo scene on the swap-locked 4 x 4 wall of examples/display_wall
// (16 tiles over 4 loopback hosts, `vrflow launch`) against one viewer of the whole wall, in one
// run. One JSON line per configuration: {tiles, hosts, payload, iterations, fps,
// bytes_per_tile_per_frame, swap_skew_us_p99, machine}. The payload is the objects the scene
// sends (rigid bodies and the net: "objects"; no fluid in this scene). `--quick`: 10 iterations.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;

std::string machine() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, model = "unknown CPU";
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  }
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " cores";
}

struct Config {
  std::string app;     // in examples/display_wall
  std::string frames;  // the folder its viewers write into
  std::regex tileInput;
  int tiles = 0;
  int hosts = 0;
};

// The 99th percentile of the spread of the tiles' swap times per frame (microseconds), from the
// swap logs; -1 without logs (one tile).
double swapSkewP99(const fs::path& frames, int tiles) {
  std::vector<std::map<long, double>> logs;
  for (int t = 0; t < tiles; ++t) {
    std::ifstream in(frames / ("t" + std::to_string(t) + ".swaps"));
    if (!in) return -1;
    std::map<long, double> swaps;
    long frame = 0;
    double seconds = 0;
    while (in >> frame >> seconds) swaps[frame] = seconds;
    logs.push_back(std::move(swaps));
  }
  std::vector<double> skews;
  for (const auto& [frame, first] : logs.front()) {
    double lo = first, hi = first;
    bool everywhere = true;
    for (const auto& log : logs) {
      const auto it = log.find(frame);
      if (it == log.end()) {
        everywhere = false;
        break;
      }
      lo = std::min(lo, it->second);
      hi = std::max(hi, it->second);
    }
    if (everywhere) skews.push_back(1e6 * (hi - lo));
  }
  if (skews.empty()) return -1;
  std::sort(skews.begin(), skews.end());
  return skews[std::min(skews.size() - 1,
                        static_cast<std::size_t>(0.99 * static_cast<double>(skews.size())))];
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  const int iterations = quick ? 10 : 100;
  const fs::path bin = fs::canonical("/proc/self/exe").parent_path();
  const fs::path examples = fs::path(VRFLOW_SOURCE_DIR) / "examples/display_wall";
  const std::string host = machine();
  const std::vector<Config> configs{
      {"display_wall_4x4.xml", "display-wall-4x4", std::regex(R"(wall:t\d+\.objects)"), 16, 4},
      {"one_view.xml", "one-view", std::regex(R"(view\.objects)"), 1, 1}};
  for (const auto& config : configs) {
    const fs::path dir = fs::temp_directory_path() / ("vrflow-bench-wall-" + config.frames);
    fs::remove_all(dir);
    fs::create_directories(dir / config.frames);
    const std::string command = "cd '" + dir.string() + "' && '" + (bin / "vrflow").string() +
                                "' launch '" + (examples / config.app).string() + "' -n " +
                                std::to_string(iterations) +
                                " --no-progress --report report.json > run.log 2>&1";
    if (std::system(command.c_str()) != 0) {
      std::fprintf(stderr, "vrflow-bench-wall: %s failed; see %s/run.log\n", config.app.c_str(),
                   dir.c_str());
      return 1;
    }
    std::ifstream in(dir / "report.json");
    const auto report = nlohmann::json::parse(in, nullptr, false);
    if (report.is_discarded()) {
      std::fprintf(stderr, "vrflow-bench-wall: no report in %s\n", dir.c_str());
      return 1;
    }
    double bytes = 0, messages = 0;
    for (const auto& c : report["connections"]) {
      if (!std::regex_match(c["to"].get<std::string>(), config.tileInput)) continue;
      bytes += c["bytes"].get<double>();
      messages += c["messages"].get<double>();
    }
    const double wall = report["timing"]["wall_s"].get<double>();
    const double skew = swapSkewP99(dir / config.frames, config.tiles);
    std::printf(
        "{\"tiles\": %d, \"hosts\": %d, \"payload\": \"objects\", \"iterations\": %d, "
        "\"fps\": %.2f, \"bytes_per_tile_per_frame\": %.0f, \"swap_skew_us_p99\": %s, "
        "\"machine\": \"%s\"}\n",
        config.tiles, config.hosts, iterations, iterations / wall,
        messages > 0 ? bytes / messages : 0.0,
        skew < 0 ? "null" : std::to_string(static_cast<long>(skew)).c_str(), host.c_str());
    std::fflush(stdout);
    fs::remove_all(dir);
  }
  return 0;
}
