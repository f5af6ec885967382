#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/record/format.hpp"

namespace vrflow::record {

/// How a recording is written.
struct WriterSettings {
  int level = 1;  ///< zstd compression level (negative: faster, larger)
  /// A chunk is compressed and written once its records reach this many bytes (or at flush()).
  std::size_t chunkBytes = std::size_t{1} << 20;
  /// zstd worker threads compressing a chunk in parallel (0: in the caller's thread). A chunk
  /// is split into jobs of about chunkBytes / workers.
  int workers = 0;
};

/// Writes one recording (docs/recording.md): the header at create(), then chunks as records
/// come, then the index and trailer at close(). Every chunk is written whole with write(), so a
/// reader may follow the file while it grows. Not thread-safe.
class RecordingWriter {
 public:
  /// Creates (or truncates) `path` and writes its header; `startNs` is the wall clock the
  /// arrival times count from (0: now).
  static Result<std::unique_ptr<RecordingWriter>> create(
      const std::string& path, const std::vector<RecordedConnection>& connections,
      WriterSettings settings = {}, std::uint64_t startNs = 0);
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  /// Appends one message of connection `connection` (an index into the header's table), sent
  /// at `iteration` and received at `arrivalNs` (wall clock, ns since the epoch).
  Status add(std::uint32_t connection, std::uint64_t iteration, std::uint64_t arrivalNs,
             std::span<const std::byte> message);
  /// Compresses and writes the records added since the last chunk (nothing when none).
  Status flush();
  /// Flushes, writes the index and the trailer, closes the file. Called by the destructor when
  /// not called before (errors then go unreported).
  Status close();

  /// Bytes of messages added so far, and bytes written to the file so far.
  std::uint64_t messageBytes() const { return messageBytes_; }
  std::uint64_t fileBytes() const { return offset_; }

 private:
  RecordingWriter() = default;
  Status writeAll(std::span<const std::byte> bytes);

  struct Compressor;
  std::unique_ptr<Compressor> zstd_;
  std::string path_;
  int fd_ = -1;
  WriterSettings settings_;
  std::uint32_t connectionCount_ = 0;
  std::uint64_t offset_ = 0;
  std::uint64_t messageBytes_ = 0;
  std::vector<std::byte> raw_;         // records of the chunk being filled
  std::vector<std::byte> compressed_;  // chunk header + zstd frame
  ChunkInfo pending_;
  std::vector<ChunkInfo> index_;
};

}  // namespace vrflow::record
