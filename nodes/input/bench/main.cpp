// vrflow-bench-input: latency from a device event to the force it causes reaching the module
// that applies it, measured in real runs (`vrflow run --trace` on bench/haptic_latency.xml and
// bench/grab_latency.xml) from the trace's spans and message flows. One JSON object per line:
//   haptic-arm: the haptic module at 1 kHz (real time) with the simulated arm; from the tick's
//     device sample (its compute span's start) to the feedback force's arrival in the module
//     that renders it (a recorder standing for the device driver);
//   grab-script: the grab with a scripted device, from its sample to its force arriving in the
//     rigid animator (the rigid cycle runs as fast as it can).
// Each line also gives the transport alone for the same messages (put() to the receiver's
// wait() returning: the runtime's floor, the baseline measured in the same run).
#include <sys/utsname.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;

/// One module's compute spans (start, end) in µs, in order.
using Spans = std::vector<std::pair<double, double>>;

struct Trace {
  std::map<std::string, Spans> compute;  ///< by module id
  /// Flows by name ("from -> to"): (put time, arrival time) in µs.
  std::map<std::string, std::vector<std::pair<double, double>>> flows;
  double wall = 0.0;  ///< s, first to last event
};

Trace readTrace(const fs::path& file) {
  const auto json = nlohmann::json::parse(std::ifstream(file));
  const auto& events = json.is_object() ? json["traceEvents"] : json;
  std::map<long, std::string> threads;
  std::map<std::pair<std::string, long>, double> starts;
  Trace trace;
  double first = 1e300, last = -1e300;
  for (const auto& e : events)
    if (e.value("ph", "") == "M" && e.value("name", "") == "thread_name")
      threads[e["tid"].get<long>()] = e["args"]["name"].get<std::string>();
  for (const auto& e : events) {
    const std::string ph = e.value("ph", "");
    if (ph == "M") continue;
    const double ts = e["ts"].get<double>();
    first = std::min(first, ts);
    last = std::max(last, ts);
    if (ph == "X" && e.value("name", "") == "compute")
      trace.compute[threads[e["tid"].get<long>()]].emplace_back(ts, ts + e["dur"].get<double>());
    if (ph == "s") starts[{e["name"].get<std::string>(), e["id"].get<long>()}] = ts;
    if (ph == "f") {
      const auto key = std::make_pair(e["name"].get<std::string>(), e["id"].get<long>());
      if (const auto found = starts.find(key); found != starts.end())
        trace.flows[key.first].emplace_back(found->second, ts);
    }
  }
  for (auto& [name, spans] : trace.compute) std::sort(spans.begin(), spans.end());
  trace.wall = (last - first) * 1e-6;
  return trace;
}

/// The start of the last span of `spans` that began at or before `time`.
double spanStart(const Spans& spans, double time) {
  auto it = std::upper_bound(spans.begin(), spans.end(), std::make_pair(time, 1e300));
  return it == spans.begin() ? time : std::prev(it)->first;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto index = static_cast<std::size_t>(p * static_cast<double>(values.size() - 1) + 0.5);
  return values[std::min(index, values.size() - 1)];
}

/// Prints one line: latency from the sender's compute start (its device sample) to the
/// arrival of `flow` in the receiver.
void report(const Trace& trace, const std::string& device, const std::string& flow,
            const std::string& sender, double rateHz, const std::string& host) {
  double load = 0.0;
  getloadavg(&load, 1);  // the machine's load while measuring (a shared machine's p99 moves)
  std::vector<double> latency, transport;
  const auto found = trace.flows.find(flow);
  if (found == trace.flows.end()) {
    std::fprintf(stderr, "vrflow-bench-input: no flow '%s' in the trace\n", flow.c_str());
    std::exit(1);
  }
  const Spans& senderSpans = trace.compute.at(sender);
  for (const auto& [put, arrived] : found->second) {
    const double begun = spanStart(senderSpans, put);
    latency.push_back((arrived - begun) * 1e-3);
    transport.push_back((arrived - put) * 1e-3);
  }
  nlohmann::json line{{"bench", "input"},
                      {"device", device},
                      {"path", flow},
                      {"rate_hz", rateHz},
                      {"latency_ms_p50", percentile(latency, 0.5)},
                      {"latency_ms_p99", percentile(latency, 0.99)},
                      {"transport_ms_p50", percentile(transport, 0.5)},
                      {"transport_ms_p99", percentile(transport, 0.99)},
                      {"samples", latency.size()},
                      {"host", host},
                      {"load1", load},
                      {"cores", std::thread::hardware_concurrency()}};
  std::printf("%s\n", line.dump().c_str());
  std::fflush(stdout);
}

/// Runs `app` (bench/ in the source tree) in `dir`, where its outputs and logs go.
int run(const fs::path& bin, const fs::path& app, const fs::path& dir, const fs::path& trace,
        int iterations) {
  const std::string command = "cd '" + dir.string() + "' && '" + (bin / "vrflow").string() +
                              "' run '" + app.string() + "' --no-progress -n " +
                              std::to_string(iterations) + " --trace '" + trace.string() +
                              "' --log-dir '" + (dir / "logs").string() + "' >/dev/null";
  return std::system(command.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  const int seconds = argc > 1 ? std::atoi(argv[1]) : 3;
  if (seconds < 1) {
    std::fprintf(stderr, "usage: vrflow-bench-input [SECONDS >= 1]\n");
    return 2;
  }
  const fs::path bin = fs::canonical("/proc/self/exe").parent_path();
  char pattern[] = "/tmp/vrflow-bench-input-XXXXXX";
  if (!mkdtemp(pattern)) return 1;
  const fs::path dir = pattern;
  const fs::path apps = VRFLOW_INPUT_BENCH_DIR;
  utsname name{};
  uname(&name);
  const std::string host = name.nodename;

  // The haptic loop: `seconds` of real time at 1 kHz, 100 physics steps a second.
  if (run(bin, apps / "haptic_latency.xml", dir, dir / "haptic.json", 100 * seconds) != 0) {
    std::fprintf(stderr, "vrflow-bench-input: the haptic run failed (logs in %s)\n", dir.c_str());
    return 1;
  }
  const Trace haptic = readTrace(dir / "haptic.json");
  const double ticks = static_cast<double>(haptic.compute.at("tool").size());
  report(haptic, "haptic-arm", "tool -> hand", "tool", ticks / haptic.wall, host);

  if (run(bin, apps / "grab_latency.xml", dir, dir / "grab.json", 200 * seconds) != 0) {
    std::fprintf(stderr, "vrflow-bench-input: the grab run failed (logs in %s)\n", dir.c_str());
    return 1;
  }
  const Trace grab = readTrace(dir / "grab.json");
  report(grab, "grab-script", "grab -> bodies", "grab",
         static_cast<double>(grab.compute.at("grab").size()) / grab.wall, host);
  fs::remove_all(dir);
  return 0;
}
