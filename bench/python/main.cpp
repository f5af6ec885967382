#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "vrflow/base/executable_dir.hpp"

// vrflow-bench-python: a pass-through module in C++ and in Python, side by side in one run of
// this program: source -> pass -> sink, through `vrflow run`, at 64 B, 1 MiB and 16 MiB. One
// JSON line per case: {language, bytes, messages, msgs_per_s, one_way_us_median, ...}.
// msgs_per_s: the source sends as fast as backpressure lets it, rate at the sink in the steady
// state. one_way_us: from the source's put() to the sink's wait() through the pass-through, one
// message in flight (a second run, the sink's endIt pacing the source).

namespace fs = std::filesystem;

namespace {

std::string q(const std::string& s) {
  return "'" + s + "'";
}

struct Case {
  std::string language;
  std::size_t bytes;
  int messages;
};

// paced: the sink's endIt paces the source (one message in flight: the one-way latency);
// otherwise the source sends as fast as backpressure lets it (the throughput).
std::string applicationXml(const Case& c, const fs::path& packages, const fs::path& arrivals,
                           bool paced) {
  const std::string pass = c.language == "python" ? "pass-python" : "pass-cpp";
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"bench-python\" "
         "version=\"1\">\n  <packages path=\"" +
         packages.string() +
         "\"/>\n  <modules>\n"
         "    <module id=\"source\" package=\"benchpython\" type=\"source\">\n"
         "      <param name=\"bytes\" value=\"" +
         std::to_string(c.bytes) + "\"/>\n" +
         (paced ? "      <input port=\"beginIt\" initial-messages=\"1\"/>\n" : "") +
         "    </module>\n"
         "    <module id=\"pass\" package=\"benchpython\" type=\"" +
         pass +
         "\"/>\n"
         "    <module id=\"sink\" package=\"benchpython\" type=\"sink\">\n"
         "      <param name=\"out\" value=\"" +
         arrivals.string() +
         "\"/>\n    </module>\n  </modules>\n  <connections>\n"
         "    <connection from=\"source.out\" to=\"pass.in\"/>\n"
         "    <connection from=\"pass.out\" to=\"sink.in\"/>\n" +
         (paced ? "    <connection from=\"sink.endIt\" to=\"source.beginIt\"/>\n" : "") +
         "  </connections>\n</application>\n";
}

struct Arrivals {
  std::vector<uint64_t> receive, latency;  // ns
};

// Runs the case once; what the sink saw, or nullopt when the run failed.
std::optional<Arrivals> runOnce(const Case& c, const fs::path& work, const fs::path& bin,
                                bool paced) {
  const std::string name = c.language + "-" + std::to_string(c.bytes) + (paced ? "-paced" : "");
  const fs::path app = work / (name + ".xml");
  const fs::path arrivals = work / (name + ".txt");
  std::ofstream(app) << applicationXml(c, VRFLOW_BENCH_PACKAGE_DIR, arrivals, paced);
  const std::string command = "cd " + q(work.string()) + " && PATH=" + q(VRFLOW_PYTHON_BIN_DIR) +
                              ":\"$PATH\" " + q((bin / "vrflow").string()) +
                              " run --no-progress --shm-size 4096 --timeout 300 --log-dir " +
                              q((work / "logs").string()) + " " + q(app.string()) + " -n " +
                              std::to_string(c.messages) + " > " + q(name + ".log") + " 2>&1";
  if (const int status = std::system(command.c_str()); status != 0) {
    std::fprintf(stderr, "vrflow-bench-python: %s failed (status %d); see %s\n", name.c_str(),
                 status, (work / (name + ".log")).c_str());
    return std::nullopt;
  }
  Arrivals seen;
  std::ifstream in(arrivals);
  for (uint64_t r = 0, l = 0; in >> r >> l;) {
    seen.receive.push_back(r);
    seen.latency.push_back(l);
  }
  if (seen.receive.size() < 4) return std::nullopt;
  return seen;
}

// Runs one case (throughput, then latency); its JSON line, or null when a run failed.
nlohmann::ordered_json runCase(const Case& c, const fs::path& work, const fs::path& bin) {
  const auto flood = runOnce(c, work, bin, /*paced=*/false);
  Case latencyCase = c;  // one message in flight: fewer suffice for the median
  latencyCase.messages = std::min(c.messages, 5000);
  const auto paced = runOnce(latencyCase, work, bin, /*paced=*/true);
  if (!flood || !paced) return nullptr;
  // The rate over the second half of the arrivals: the steady state, after the start-up burst
  // of what queued while the pass-through started.
  const std::vector<uint64_t>& receive = flood->receive;
  const std::size_t half = receive.size() / 2;
  const double seconds = static_cast<double>(receive.back() - receive[half]) * 1e-9;
  std::vector<uint64_t> latency(paced->latency.begin() + 1, paced->latency.end());
  std::sort(latency.begin(), latency.end());
  const auto at = [&](double f) {
    return static_cast<double>(
               latency[static_cast<std::size_t>(f * static_cast<double>(latency.size() - 1))]) *
           1e-3;
  };
  char host[256] = "";
  gethostname(host, sizeof host - 1);
  return {{"bench", "python"},
          {"language", c.language},
          {"bytes", c.bytes},
          {"messages", receive.size()},
          {"msgs_per_s", static_cast<double>(receive.size() - 1 - half) / seconds},
          {"one_way_us_median", at(0.5)},
          {"one_way_us_p99", at(0.99)},
          {"host", host},
          {"cpus", std::thread::hardware_concurrency()}};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"vrflow-bench-python: a pass-through module in C++ and in Python, side by side"};
  bool quick = false;
  int repeats = 1;
  cli.add_flag("--quick", quick, "Few messages (checks that the benchmark runs)");
  cli.add_option("--repeats", repeats, "Runs of each case (alternating languages)")
      ->check(CLI::Range(1, 100));
  CLI11_PARSE(cli, argc, argv);

  const fs::path bin = vrflow::executableDir();
  const fs::path work =
      fs::temp_directory_path() / ("vrflow-bench-python-" + std::to_string(getpid()));
  fs::create_directories(work);
  const int scale = quick ? 200 : 1;
  const std::vector<std::pair<std::size_t, int>> sizes{
      {64, 200000 / scale}, {1u << 20, 20000 / scale}, {16u << 20, 4000 / scale}};
  int failed = 0;
  for (int r = 0; r < repeats; ++r) {
    for (const auto& [bytes, messages] : sizes) {
      for (const char* language : {"cpp", "python"}) {
        const nlohmann::ordered_json line = runCase({language, bytes, messages}, work, bin);
        if (line.is_null()) {
          ++failed;
          continue;
        }
        std::printf("%s\n", line.dump().c_str());
        std::fflush(stdout);
      }
    }
  }
  if (failed == 0) fs::remove_all(work);
  return failed == 0 ? 0 : 1;
}
