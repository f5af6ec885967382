#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/record/format.hpp"
#include "vrflow/record/reader.hpp"

namespace vrflow::record {

/// What `vrflow inspect` says of one recorded connection.
struct ConnectionSummary {
  RecordedConnection connection;
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;  ///< message bytes
  std::uint64_t firstIteration = 0;
  std::uint64_t lastIteration = 0;
  std::uint64_t firstArrivalNs = 0;
  std::uint64_t lastArrivalNs = 0;
  /// Messages per second between the first and the last arrival (0 with fewer than two).
  double rateHz() const;
};

/// What `vrflow inspect` says of a recording (as `ros2 bag info`).
struct Summary {
  std::string path;
  std::uint32_t version = kFormatVersion;
  bool closed = false;        ///< index read from the file (else rebuilt by scanning)
  bool beingWritten = false;  ///< read as a growing file: what was there when it was read
  std::uint64_t fileBytes = 0;
  std::uint64_t messageBytes = 0;  ///< uncompressed message bytes
  std::uint64_t rawBytes = 0;      ///< chunks before compression (records with their headers)
  std::uint64_t compressedBytes = 0;
  std::uint64_t chunks = 0;
  std::uint64_t messages = 0;
  std::uint64_t startNs = 0;  ///< the first arrival (0 when empty)
  std::uint64_t endNs = 0;    ///< the last arrival
  std::vector<ConnectionSummary> connections;
  double durationSeconds() const;
};

/// Reads every chunk of `reader` (checking each) and sums it up.
Result<Summary> summarize(RecordingReader& reader);
/// The summary as aligned text lines.
std::string formatSummary(const Summary& summary);
/// The summary as one JSON object (docs/recording.md, "vrflow inspect").
std::string summaryJson(const Summary& summary);

}  // namespace vrflow::record
