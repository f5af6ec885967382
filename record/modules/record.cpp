// record/record: writes every message it receives to a recording (docs/recording.md) with its
// stamps and arrival time. Fed by the recorded outputs (through a `multiplex` filter when there
// are several, so that each message is written as it comes); `vrflow record` wires it.
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "vrflow/base/echo.hpp"
#include "vrflow/base/file_access.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"
#include "vrflow/record/connections_param.hpp"
#include "vrflow/record/writer.hpp"

namespace {

std::uint64_t wallNs() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

// The connection of a message: the only one, or the one whose module sent it.
std::optional<std::uint32_t> connectionOf(
    const std::vector<vrflow::record::RecordedConnection>& connections, std::string_view source) {
  if (connections.size() == 1) return 0;
  for (std::size_t i = 0; i < connections.size(); ++i) {
    if (connections[i].module == source) return static_cast<std::uint32_t>(i);
  }
  return std::nullopt;
}

}  // namespace

int main() {
  using namespace vrflow;
  constexpr const char* kProgram = "vrflow-record-record";
  Module module;
  auto& in = module.addInput("in");
  if (!initOrReport(module, kProgram)) return 2;
  const auto fail = [&](const std::string& why) {
    std::fprintf(stderr, "%s: module %s: %s\n", kProgram, quotedValue(module.id()).c_str(),
                 why.c_str());
    return 2;
  };
  auto connections = record::parseConnectionsParam(module.params().getString("connections"));
  if (!connections) return fail("parameter 'connections': " + connections.error().message);
  const std::string path = module.params().getString("file");
  if (auto folder = prepareOutputPath(path); !folder) {
    return fail("cannot write " + quotedValue(path) + ": " + folder.error().message);
  }
  record::WriterSettings settings;
  settings.level = static_cast<int>(module.params().getInt("level"));
  settings.chunkBytes = static_cast<std::size_t>(module.params().getInt("chunk-kib")) * 1024;
  settings.workers = static_cast<int>(module.params().getInt("workers"));
  const auto flushNs = static_cast<std::uint64_t>(module.params().getInt("flush-ms")) * 1000000;
  auto writer = record::RecordingWriter::create(path, *connections, settings);
  if (!writer) return fail(writer.error().message);
  std::uint64_t lastFlushNs = wallNs();
  while (module.wait()) {
    const Message& message = module.get(in);
    const std::uint64_t now = wallNs();
    const auto stamps = message->stamps();
    const auto index = connectionOf(*connections, stamps.source);
    if (!index) {
      return fail("a message from " + quotedValue(std::string(stamps.source)) +
                  " matches none of the recorded connections (parameter 'connections')");
    }
    auto added = (*writer)->add(*index, stamps.iteration, now, message->bytes());
    if (added && now - lastFlushNs >= flushNs) {
      added = (*writer)->flush();
      lastFlushNs = now;
    }
    if (!added) return fail(added.error().message);
  }
  if (auto closed = (*writer)->close(); !closed) return fail(closed.error().message);
  return module.exitStatus();
}
