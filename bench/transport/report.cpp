#include <sched.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "transport_bench.hpp"

namespace vrflow::bench {

namespace {

// Rounds to a number of decimals; dividing by the exact power of ten keeps the printed form short.
double roundTo(double value, double scale) {
  return std::round(value * scale) / scale;
}

std::string cpuModel() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("model name", 0) == 0) {
      const std::size_t colon = line.find(':');
      if (colon != std::string::npos) {
        const std::size_t start = line.find_first_not_of(' ', colon + 1);
        return start == std::string::npos ? std::string("unknown CPU") : line.substr(start);
      }
    }
  }
  return "unknown CPU";
}

}  // namespace

std::string machineDescription() {
  // Online logical CPUs: what the kernel can schedule our processes on.
  static const std::string description =
      cpuModel() + ", " + std::to_string(sysconf(_SC_NPROCESSORS_ONLN)) + " cores";
  return description;
}

std::vector<int> allowedCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::vector<int> cpus;
  if (sched_getaffinity(0, sizeof set, &set) != 0) return cpus;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &set)) cpus.push_back(cpu);
  return cpus;
}

std::string idlePolicy() {
  // What an idle core does here decides what waking it costs (docs/shared-memory.md): a VM guest
  // whose cores halt at once pays tens of microseconds per wake-up of an idle core.
  static const std::string policy = [] {
    std::ifstream driverFile("/sys/devices/system/cpu/cpuidle/current_driver");
    std::string driver;
    if (!std::getline(driverFile, driver) || driver.empty()) return std::string("unknown");
    if (driver != "haltpoll") return driver;
    std::ifstream pollFile("/sys/module/haltpoll/parameters/guest_halt_poll_ns");
    std::string poll;
    if (!std::getline(pollFile, poll) || poll.empty()) return driver;
    return driver + ", guest_halt_poll_ns " + poll;
  }();
  return policy;
}

std::string toJsonLine(const BenchResult& result) {
  const nlohmann::ordered_json line = {
      {"transport", result.transport},
      {"bytes", result.bytes},
      {"one_way_us_median", roundTo(result.oneWayUsMedian, 1000.0)},
      {"one_way_us_p99", roundTo(result.oneWayUsP99, 1000.0)},
      {"msgs_per_s", roundTo(result.msgsPerS, 10.0)},
      {"machine", machineDescription()},
      {"cpuidle", idlePolicy()},
      {"detail", result.detail},
  };
  return line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

Result<BenchResult> parseJsonLine(std::string_view line) {
  const auto json = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded() || !json.is_object()) {
    return makeError("not a JSON object: " + std::string(line));
  }
  const auto field = [&json](const char* name) {
    return json.contains(name) ? json[name] : nullptr;
  };
  const auto transport = field("transport");
  const auto bytes = field("bytes");
  const auto median = field("one_way_us_median");
  const auto p99 = field("one_way_us_p99");
  const auto rate = field("msgs_per_s");
  if (!transport.is_string() || !bytes.is_number_unsigned() || !median.is_number() ||
      !p99.is_number() || !rate.is_number()) {
    return makeError("JSON line lacks a result field: " + std::string(line));
  }
  BenchResult result;
  result.transport = transport.get<std::string>();
  result.bytes = bytes.get<std::size_t>();
  result.oneWayUsMedian = median.get<double>();
  result.oneWayUsP99 = p99.get<double>();
  result.msgsPerS = rate.get<double>();
  const auto detail = field("detail");
  if (detail.is_string()) {
    result.detail = detail.get<std::string>();
  }
  return result;
}

}  // namespace vrflow::bench
