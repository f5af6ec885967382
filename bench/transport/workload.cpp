#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "transport_bench.hpp"

namespace vrflow::bench {

namespace {

constexpr std::size_t kKiB = 1024;
constexpr std::size_t kMiB = 1024 * kKiB;
// MPI counts are int; stay far below that and below what the machine can hold twice.
constexpr std::size_t kMaxMessageBytes = 256 * kMiB;

std::string_view trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())) != 0) {
    text.remove_prefix(1);
  }
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())) != 0) {
    text.remove_suffix(1);
  }
  return text;
}

Result<std::size_t> parseOneSize(std::string_view item) {
  item = trim(item);
  std::size_t number = 0;
  const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), number);
  if (ec != std::errc{} || end == item.data()) {
    return makeError("bad size '" + std::string(item) +
                     "': expected a number such as 64, 4K or 1M");
  }
  std::string unit(end, item.data() + item.size());
  std::transform(unit.begin(), unit.end(), unit.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::size_t scale = 1;
  if (unit == "k" || unit == "kib" || unit == "kb") {
    scale = kKiB;
  } else if (unit == "m" || unit == "mib" || unit == "mb") {
    scale = kMiB;
  } else if (!unit.empty() && unit != "b") {
    return makeError("bad size unit in '" + std::string(item) + "': use B, K (KiB) or M (MiB)");
  }
  if (number == 0 || number > kMaxMessageBytes / scale) {
    return makeError("size '" + std::string(item) + "' is out of range (1 B to 256 MiB)");
  }
  return number * scale;
}

}  // namespace

std::vector<std::size_t> benchSizes() {
  return {64, 4 * kKiB, kMiB, 16 * kMiB};
}

Result<std::vector<std::size_t>> parseSizes(std::string_view text) {
  std::vector<std::size_t> sizes;
  while (!text.empty()) {
    const std::size_t comma = text.find(',');
    auto size = parseOneSize(text.substr(0, comma));
    if (!size) {
      return size.error();
    }
    sizes.push_back(*size);
    text = comma == std::string_view::npos ? std::string_view{} : text.substr(comma + 1);
  }
  if (sizes.empty()) {
    return makeError("no message sizes given");
  }
  return sizes;
}

IterationPlan iterationPlan(std::size_t bytes, bool quick) {
  // Bound the bytes moved per phase rather than the message count, so that small messages get
  // many samples (20000 round trips at 64 B) and 16 MiB ones still finish in about a second.
  constexpr std::size_t kPingPongBytes = 1024 * kMiB;
  constexpr std::size_t kStreamBytes = 4096 * kMiB;
  IterationPlan plan;
  plan.pingPongs = std::clamp<std::size_t>(kPingPongBytes / bytes, 100, 20'000);
  plan.streamMessages = std::clamp<std::size_t>(kStreamBytes / bytes, 256, 200'000);
  plan.warmupMessages = std::max<std::size_t>(plan.pingPongs / 20, 10);
  if (quick) {
    plan.pingPongs = std::max<std::size_t>(plan.pingPongs / 100, 10);
    plan.streamMessages = std::max<std::size_t>(plan.streamMessages / 100, 16);
    plan.warmupMessages = 4;
  }
  return plan;
}

std::size_t streamQueueDepth(std::size_t bytes) {
  constexpr std::size_t kQueueBytes = 64 * kMiB;
  return std::clamp<std::size_t>(kQueueBytes / bytes, 2, 1000);
}

std::vector<unsigned char> makePayload(std::size_t bytes) {
  std::vector<unsigned char> payload(bytes);
  for (std::size_t i = 0; i < bytes; ++i) {
    payload[i] = static_cast<unsigned char>(i * 131 + 7);
  }
  return payload;
}

}  // namespace vrflow::bench
