#include "vrflow/camera/capture_latency.hpp"

#include <algorithm>

#include "vrflow/camera/capture_stamps.hpp"
#include "vrflow/message/reader.hpp"
#include "vrflow/record/reader.hpp"

namespace vrflow::camera {

Result<std::map<std::string, LatencyFrames>> latencyFrames(const std::string& recording,
                                                           std::string_view stamp) {
  auto reader = record::RecordingReader::open(recording);
  if (!reader) return reader.error();
  std::map<std::string, LatencyFrames> byConnection;
  for (std::size_t chunk = 0; chunk < (*reader)->chunks().size(); ++chunk) {
    auto records = (*reader)->readChunk(chunk);
    if (!records) return records.error();
    for (const auto& record : *records) {
      auto message = msg::MessageView::parse(record.message);
      if (!message) return Error{recording + ": " + message.error().message};
      const auto used = int64Stamp(*message, stamp);
      if (!used) continue;
      const auto iteration = static_cast<std::int64_t>(record.iteration);
      const std::int64_t frames = iteration - *used;
      auto& entry = byConnection[(*reader)->connections()[record.connection].name()];
      if (entry.messages == 0) {
        entry.min = entry.max = frames;
        entry.firstUseIteration = iteration;
      }
      entry.min = std::min(entry.min, frames);
      entry.max = std::max(entry.max, frames);
      entry.firstUseIteration = std::min(entry.firstUseIteration, iteration);
      ++entry.messages;
    }
  }
  return byConnection;
}

}  // namespace vrflow::camera
