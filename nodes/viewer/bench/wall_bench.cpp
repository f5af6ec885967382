// vrflow-bench-wall: the paper's scene with its fluid on the swap-locked 4 x 4 wall of
// examples/display_wall (16 tiles over 4 loopback hosts, `vrflow launch`) against one viewer of
// the whole wall, in one run. One JSON line per configuration: {tiles, hosts, payload, routing,
// swap_margin_ms, iterations, fps, bytes_per_tile_per_frame, liquid_bytes_per_tile_per_frame,
// wall_bytes_per_frame, swap_skew_us_p50, swap_skew_us_p99, machine}.
// - payload "surface": the liquid's surface regions routed per tile (the example as it is);
// - payload "particles", routing "broadcast": the particles sent whole to every tile (the
//   paper's failure case): the route's volumes are never sent (its `stamp` renamed), so every
//   tile keeps `initially="all"`;
// - the surface wall again with swap-margin (the swaps released at an absolute time);
// - one view through the whole wall, the surface drawn.
// `--iterations N` (default 100); `--quick`: 10.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
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
  std::string payload;
  std::string routing;
  std::string settings;  // --set arguments
  double swapMarginMs = 0;
  std::regex tileInput;
  int tiles = 0;
  int hosts = 0;
};

struct Skew {
  double p50 = -1, p99 = -1;
};

// The spread of the tiles' swap times per frame (microseconds), from the swap logs: its 50th
// and 99th percentiles; -1 without logs (one tile).
Skew swapSkew(const fs::path& frames, int tiles) {
  std::vector<std::map<long, double>> logs;
  for (int t = 0; t < tiles; ++t) {
    std::ifstream in(frames / ("t" + std::to_string(t) + ".swaps"));
    if (!in) return {};
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
  if (skews.empty()) return {};
  std::sort(skews.begin(), skews.end());
  const auto at = [&skews](double q) {
    return skews[std::min(skews.size() - 1,
                          static_cast<std::size_t>(q * static_cast<double>(skews.size())))];
  };
  return {at(0.5), at(0.99)};
}

std::string orNull(double value) {
  return value < 0 ? "null" : std::to_string(static_cast<long>(value));
}

}  // namespace

int main(int argc, char** argv) {
  int iterations = 100;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--quick") {
      iterations = 10;
    } else if (arg == "--iterations" && i + 1 < argc) {
      iterations = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: vrflow-bench-wall [--quick | --iterations N]\n");
      return 2;
    }
  }
  if (iterations < 2) {
    std::fprintf(stderr, "vrflow-bench-wall: --iterations must be at least 2\n");
    return 2;
  }
  const fs::path bin = fs::canonical("/proc/self/exe").parent_path();
  const fs::path examples = fs::path(VRFLOW_SOURCE_DIR) / "examples/display_wall";
  const std::string host = machine();
  const std::regex wallTiles(R"(wall:t\d+\.objects)");
  const std::vector<Config> configs{
      {"display_wall_4x4.xml", "display-wall-4x4", "surface", "route", "", 0, wallTiles, 16, 4},
      {"display_wall_4x4.xml", "display-wall-4x4", "particles", "broadcast",
       "--set water.surface=off --set wall:liquid.stamp=never-sent", 0, wallTiles, 16, 4},
      {"display_wall_4x4.xml", "display-wall-4x4", "surface", "route", "--set wall.swap_margin=30",
       30, wallTiles, 16, 4},
      {"one_view.xml", "one-view", "surface", "direct", "", 0, std::regex(R"(view\.objects)"), 1,
       1}};
  for (const auto& config : configs) {
    const fs::path dir = fs::temp_directory_path() / ("vrflow-bench-wall-" + config.frames);
    fs::remove_all(dir);
    fs::create_directories(dir / config.frames);
    const std::string command = "cd '" + dir.string() + "' && '" + (bin / "vrflow").string() +
                                "' launch '" + (examples / config.app).string() + "' -n " +
                                std::to_string(iterations) + " " + config.settings +
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
    // Bytes into the tiles' objects inputs; the liquid's: those from the route (the wall) or
    // the fluid (one view).
    double bytes = 0, liquid = 0;
    for (const auto& c : report["connections"]) {
      if (!std::regex_match(c["to"].get<std::string>(), config.tileInput)) continue;
      const std::string from = c["from"];
      bytes += c["bytes"].get<double>();
      if (from.rfind("wall:liquid.", 0) == 0 || from == "water.fluid") {
        liquid += c["bytes"].get<double>();
      }
    }
    const double frames = static_cast<double>(iterations);
    const double wall = report["timing"]["wall_s"].get<double>();
    const Skew skew = swapSkew(dir / config.frames, config.tiles);
    std::printf(
        "{\"tiles\": %d, \"hosts\": %d, \"payload\": \"%s\", \"routing\": \"%s\", "
        "\"swap_margin_ms\": %g, \"iterations\": %d, \"fps\": %.2f, "
        "\"bytes_per_tile_per_frame\": %.0f, \"liquid_bytes_per_tile_per_frame\": %.0f, "
        "\"wall_bytes_per_frame\": %.0f, \"swap_skew_us_p50\": %s, \"swap_skew_us_p99\": %s, "
        "\"machine\": \"%s\"}\n",
        config.tiles, config.hosts, config.payload.c_str(), config.routing.c_str(),
        config.swapMarginMs, iterations, frames / wall, bytes / (config.tiles * frames),
        liquid / (config.tiles * frames), bytes / frames, orNull(skew.p50).c_str(),
        orNull(skew.p99).c_str(), host.c_str());
    std::fflush(stdout);
    fs::remove_all(dir);
  }
  return 0;
}
