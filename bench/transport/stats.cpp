#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "transport_bench.hpp"
#include "vrflow/base/assert.hpp"

namespace vrflow::bench {

double medianNs(std::vector<std::int64_t> samplesNs) {
  VRFLOW_ASSERT(!samplesNs.empty(), "median of no samples");
  const std::size_t mid = samplesNs.size() / 2;
  std::nth_element(samplesNs.begin(), samplesNs.begin() + static_cast<std::ptrdiff_t>(mid),
                   samplesNs.end());
  const auto upper = static_cast<double>(samplesNs[mid]);
  if (samplesNs.size() % 2 == 1) {
    return upper;
  }
  // Even count: the lower middle is the largest element of the left part.
  const auto lower = static_cast<double>(
      *std::max_element(samplesNs.begin(), samplesNs.begin() + static_cast<std::ptrdiff_t>(mid)));
  return (lower + upper) / 2.0;
}

double p99Ns(std::vector<std::int64_t> samplesNs) {
  VRFLOW_ASSERT(!samplesNs.empty(), "percentile of no samples");
  // Nearest rank: the smallest sample with at least 99 % of the samples at or below it.
  const auto rank =
      static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(samplesNs.size())));
  const std::size_t index = std::max<std::size_t>(rank, 1) - 1;
  std::nth_element(samplesNs.begin(), samplesNs.begin() + static_cast<std::ptrdiff_t>(index),
                   samplesNs.end());
  return static_cast<double>(samplesNs[index]);
}

LatencySummary summarizeLatency(std::vector<std::int64_t> samplesNs) {
  LatencySummary summary;
  summary.p99Ns = p99Ns(samplesNs);
  summary.medianNs = medianNs(std::move(samplesNs));
  return summary;
}

BenchResult makeResult(std::string transport, std::size_t bytes,
                       const std::vector<std::int64_t>& roundTripNs, double msgsPerS,
                       std::string detail) {
  const LatencySummary roundTrip = summarizeLatency(roundTripNs);
  BenchResult result;
  result.transport = std::move(transport);
  result.bytes = bytes;
  result.oneWayUsMedian = roundTrip.medianNs / 2.0 / 1000.0;
  result.oneWayUsP99 = roundTrip.p99Ns / 2.0 / 1000.0;
  result.msgsPerS = msgsPerS;
  result.detail = std::move(detail);
  return result;
}

}  // namespace vrflow::bench
