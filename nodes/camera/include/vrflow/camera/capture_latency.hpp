#pragma once
// The capture-to-interactor latency in frames, read from a recording (`vrflow record`) of the
// interactors' outputs: each message an interactor sends at its iteration k carries the capture
// iteration c of the user it solved against (capture_stamps.hpp), and k - c is how many frames
// the user object was behind the capture when it was used.

#include <cstdint>
#include <map>
#include <string>

#include "vrflow/base/result.hpp"

namespace vrflow::camera {

/// Frames between capture and use over the stamped messages of one recorded connection.
struct LatencyFrames {
  std::int64_t min = 0;
  std::int64_t max = 0;
  std::uint64_t messages = 0;          ///< messages carrying the stamp
  std::int64_t firstUseIteration = 0;  ///< the iteration of the first of them
};

/// Per recorded connection ("module.port") whose messages carry `stamp`: the spread of the
/// sender's iteration minus the stamp. An error naming the file when it cannot be read.
Result<std::map<std::string, LatencyFrames>> latencyFrames(const std::string& recording,
                                                           std::string_view stamp);

}  // namespace vrflow::camera
