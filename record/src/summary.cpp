#include "vrflow/record/summary.hpp"

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <nlohmann/json.hpp>

namespace vrflow::record {

double ConnectionSummary::rateHz() const {
  if (messages < 2 || lastArrivalNs <= firstArrivalNs) return 0.0;
  return static_cast<double>(messages - 1) * 1e9 /
         static_cast<double>(lastArrivalNs - firstArrivalNs);
}

double Summary::durationSeconds() const {
  return endNs > startNs ? static_cast<double>(endNs - startNs) / 1e9 : 0.0;
}

Result<Summary> summarize(RecordingReader& reader) {
  Summary s;
  s.path = reader.path();
  s.version = reader.version();
  s.closed = reader.closed();
  s.beingWritten = reader.growing() && !reader.closed();
  s.fileBytes = reader.usedBytes();
  for (const auto& c : reader.connections()) s.connections.push_back({.connection = c});
  s.chunks = reader.chunks().size();
  for (std::size_t i = 0; i < reader.chunks().size(); ++i) {
    const ChunkInfo& chunk = reader.chunks()[i];
    s.rawBytes += chunk.rawBytes;
    s.compressedBytes += chunk.compressedBytes;
    auto records = reader.readChunk(i);
    if (!records) return records.error();
    for (const RecordView& r : *records) {
      ConnectionSummary& c = s.connections[r.connection];
      if (c.messages == 0) {
        c.firstIteration = r.iteration;
        c.firstArrivalNs = r.arrivalNs;
      }
      c.lastIteration = r.iteration;
      c.lastArrivalNs = r.arrivalNs;
      ++c.messages;
      c.bytes += r.message.size();
      if (s.messages == 0 || r.arrivalNs < s.startNs) s.startNs = r.arrivalNs;
      s.endNs = std::max(s.endNs, r.arrivalNs);
      ++s.messages;
      s.messageBytes += r.message.size();
    }
  }
  return s;
}

namespace {

std::string mib(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  return text;
}

std::string utc(std::uint64_t ns) {
  const std::time_t seconds = static_cast<std::time_t>(ns / 1000000000);
  std::tm parts{};
  gmtime_r(&seconds, &parts);
  char text[64];
  std::snprintf(text, sizeof text, "%04d-%02d-%02dT%02d:%02d:%02d.%03uZ", parts.tm_year + 1900,
                parts.tm_mon + 1, parts.tm_mday, parts.tm_hour, parts.tm_min, parts.tm_sec,
                static_cast<unsigned>(ns % 1000000000 / 1000000));
  return text;
}

double ratio(const Summary& s) {
  return s.compressedBytes > 0
             ? static_cast<double>(s.rawBytes) / static_cast<double>(s.compressedBytes)
             : 0.0;
}

}  // namespace

std::string formatSummary(const Summary& s) {
  std::string out;
  char line[512];
  const auto add = [&](const char* label, const std::string& value) {
    std::snprintf(line, sizeof line, "%-15s %s\n", label, value.c_str());
    out += line;
  };
  add("File:", s.path);
  add("Format version:", std::to_string(s.version));
  add("Index:", s.closed         ? "written at close"
                : s.beingWritten ? "none yet: the file is being written (what it held so far)"
                                 : "rebuilt by scanning (the file was not closed)");
  std::snprintf(line, sizeof line, "%s (messages %s, zstd ratio %.2f)", mib(s.fileBytes).c_str(),
                mib(s.messageBytes).c_str(), ratio(s));
  add("Size:", line);
  std::snprintf(line, sizeof line, "%.3f s", s.durationSeconds());
  add("Duration:", line);
  add("Start:", s.messages > 0 ? utc(s.startNs) : "-");
  add("End:", s.messages > 0 ? utc(s.endNs) : "-");
  add("Chunks:", std::to_string(s.chunks));
  add("Messages:", std::to_string(s.messages));
  add("Connections:", std::to_string(s.connections.size()));
  for (const auto& c : s.connections) {
    std::snprintf(line, sizeof line,
                  "  %s | type %s | %llu messages | %.2f Hz | %s | iterations %llu-%llu\n",
                  c.connection.name().c_str(), c.connection.data.c_str(),
                  static_cast<unsigned long long>(c.messages), c.rateHz(), mib(c.bytes).c_str(),
                  static_cast<unsigned long long>(c.firstIteration),
                  static_cast<unsigned long long>(c.lastIteration));
    out += line;
  }
  return out;
}

std::string summaryJson(const Summary& s) {
  nlohmann::ordered_json j;
  j["file"] = s.path;
  j["version"] = s.version;
  j["closed"] = s.closed;
  j["being_written"] = s.beingWritten;
  j["file_bytes"] = s.fileBytes;
  j["message_bytes"] = s.messageBytes;
  j["raw_bytes"] = s.rawBytes;
  j["compressed_bytes"] = s.compressedBytes;
  j["compression_ratio"] = ratio(s);
  j["chunks"] = s.chunks;
  j["messages"] = s.messages;
  j["start_ns"] = s.startNs;
  j["end_ns"] = s.endNs;
  j["duration_s"] = s.durationSeconds();
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const auto& c : s.connections) {
    nlohmann::ordered_json e;
    e["name"] = c.connection.name();
    e["module"] = c.connection.module;
    e["port"] = c.connection.port;
    e["data"] = c.connection.data;
    e["messages"] = c.messages;
    e["bytes"] = c.bytes;
    e["rate_hz"] = c.rateHz();
    e["first_iteration"] = c.firstIteration;
    e["last_iteration"] = c.lastIteration;
    list.push_back(e);
  }
  j["connections"] = list;
  // Names come from the file: bytes that are not UTF-8 become U+FFFD instead of throwing.
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace vrflow::record
