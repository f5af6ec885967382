// vrflow-bench-record: the recorder's writer and the replay's reader against plain write() of
// the same message bytes, in the same run. One JSON object per line (docs/recording.md,
// "Benchmark"): {record_mib_s, replay_mib_s, write_mib_s}; the target is record >= 0.8x write.
#include <fcntl.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "vrflow/message/builder.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/record/reader.hpp"
#include "vrflow/record/writer.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A fluid-like stream: per message a 32^3 scalar field that moves smoothly, and 64 rigid
// bodies' positions (the paper scene's two kinds of traffic).
std::vector<std::vector<std::byte>> makeMessages(int count) {
  std::vector<std::vector<std::byte>> messages;
  std::vector<float> field(32 * 32 * 32);
  for (int m = 0; m < count; ++m) {
    vrflow::msg::VectorSink sink;
    vrflow::msg::MessageBuilder builder(sink);
    builder.setSource("fluid");
    builder.setIteration(static_cast<std::uint64_t>(m));
    builder.setSimTime(0.01 * m);
    builder.setTimeStep(0.01);
    for (std::size_t i = 0; i < field.size(); ++i) {
      field[i] = std::sin(0.05f * static_cast<float>(i % 977) + 0.1f * static_cast<float>(m)) *
                 static_cast<float>(i % 32);
    }
    builder.addField(1, true, {32, 32, 32}, 1, {0, 0, 0}, 0.1, field);
    for (std::uint64_t body = 0; body < 64; ++body) {
      auto object = builder.addObject(100 + body, vrflow::msg::pointType());
      const double t = 0.01 * m + static_cast<double>(body);
      object.set(vrflow::msg::PointParam::kPosition,
                 vrflow::msg::Vec3{std::cos(t), std::sin(t), 0.1 * t});
    }
    const std::size_t size = builder.finish();
    messages.emplace_back(builder.bytes().begin(),
                          builder.bytes().begin() + static_cast<long>(size));
  }
  return messages;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"vrflow-bench-record: recording and replay throughput against plain write()"};
  int count = 512, repeats = 3, level = 1, workers = 0, chunkKib = 1024;
  std::string dir = "/tmp";
  cli.add_option("--messages", count, "Messages per pass")->check(CLI::Range(1, 100000));
  cli.add_option("--repeats", repeats, "Passes (one line each)")->check(CLI::Range(1, 100));
  cli.add_option("--level", level, "zstd level of the recording")->check(CLI::Range(-7, 19));
  cli.add_option("--workers", workers, "zstd worker threads")->check(CLI::Range(0, 64));
  cli.add_option("--chunk-kib", chunkKib, "Chunk size (KiB)")->check(CLI::Range(1, 1 << 20));
  cli.add_option("--dir", dir, "Folder for the files written (removed after)");
  CLI11_PARSE(cli, argc, argv);

  const auto messages = makeMessages(count);
  std::uint64_t bytes = 0;
  for (const auto& m : messages) bytes += m.size();
  const double mib = static_cast<double>(bytes) / (1024.0 * 1024.0);
  const std::string plainPath = dir + "/vrflow-bench-record-" + std::to_string(getpid()) + ".raw";
  const std::string recordPath =
      dir + "/vrflow-bench-record-" + std::to_string(getpid()) + ".vrrec";
  char host[256] = "unknown";
  gethostname(host, sizeof host - 1);
  for (int pass = 0; pass < repeats; ++pass) {
    // Peer: the same bytes with plain write(), one call per message.
    auto start = Clock::now();
    const int fd = ::open(plainPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
      std::perror(plainPath.c_str());
      return 1;
    }
    for (const auto& m : messages) {
      if (::write(fd, m.data(), m.size()) != static_cast<ssize_t>(m.size())) {
        std::perror("write");
        return 1;
      }
    }
    ::close(fd);
    const double writeS = secondsSince(start);

    // The recording, the same bytes: first with the caller compressing every chunk (the writer
    // before its compression thread), then as the recorder writes them.
    struct Recorded {
      double seconds = 0;
      std::uint64_t fileBytes = 0, storedChunks = 0, chunks = 0;
    };
    const auto record = [&](bool thread) -> std::optional<Recorded> {
      const auto begin = Clock::now();
      auto writer = vrflow::record::RecordingWriter::create(
          recordPath, {{"fluid", "objects", "objects"}},
          {.level = level,
           .chunkBytes = static_cast<std::size_t>(chunkKib) * 1024,
           .workers = workers,
           .compressionThread = thread});
      if (!writer) {
        std::fprintf(stderr, "%s\n", writer.error().message.c_str());
        return std::nullopt;
      }
      std::uint64_t iteration = 0;
      for (const auto& m : messages) {
        if (auto added = (*writer)->add(0, iteration, 1000 + iteration, m); !added) {
          std::fprintf(stderr, "%s\n", added.error().message.c_str());
          return std::nullopt;
        }
        ++iteration;
      }
      if (auto closed = (*writer)->close(); !closed) {
        std::fprintf(stderr, "%s\n", closed.error().message.c_str());
        return std::nullopt;
      }
      return Recorded{secondsSince(begin), (*writer)->fileBytes(), (*writer)->storedChunks(),
                      (*writer)->chunksWritten()};
    };
    const auto inlined = record(false);
    if (!inlined) return 1;
    const auto recorded = record(true);
    if (!recorded) return 1;
    const double recordS = recorded->seconds;
    const std::uint64_t fileBytes = recorded->fileBytes;

    // Replay's side: open, decompress and check every message (layout included).
    start = Clock::now();
    auto reader = vrflow::record::RecordingReader::open(recordPath);
    std::uint64_t read = 0;
    if (!reader) {
      std::fprintf(stderr, "%s\n", reader.error().message.c_str());
      return 1;
    }
    for (std::size_t c = 0; c < (*reader)->chunks().size(); ++c) {
      auto records = (*reader)->readChunk(c);
      if (!records) {
        std::fprintf(stderr, "%s\n", records.error().message.c_str());
        return 1;
      }
      for (const auto& r : *records) read += r.message.size();
    }
    const double replayS = secondsSince(start);
    if (read != bytes) {
      std::fprintf(stderr, "replay read %llu bytes of %llu\n",
                   static_cast<unsigned long long>(read), static_cast<unsigned long long>(bytes));
      return 1;
    }
    std::printf(
        "{\"bench\":\"record\",\"host\":\"%s\",\"pass\":%d,\"messages\":%d,\"mib\":%.2f,"
        "\"level\":%d,\"workers\":%d,\"chunk_kib\":%d,\"record_mib_s\":%.1f,\"replay_mib_s\":%.1f,"
        "\"write_mib_s\":%.1f,\"record_over_write\":%.3f,\"compression_ratio\":%.2f,"
        "\"stored_chunks\":%llu,\"chunks\":%llu,\"record_inline_mib_s\":%.1f,"
        "\"inline_over_write\":%.3f,\"inline_compression_ratio\":%.2f}\n",
        host, pass, count, mib, level, workers, chunkKib, mib / recordS, mib / replayS,
        mib / writeS, writeS / recordS, static_cast<double>(bytes) / static_cast<double>(fileBytes),
        static_cast<unsigned long long>(recorded->storedChunks),
        static_cast<unsigned long long>(recorded->chunks), mib / inlined->seconds,
        writeS / inlined->seconds,
        static_cast<double>(bytes) / static_cast<double>(inlined->fileBytes));
  }
  ::unlink(plainPath.c_str());
  ::unlink(recordPath.c_str());
  return 0;
}
