#pragma once

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/record/format.hpp"

namespace vrflow::record {

/// How a recording is written.
struct WriterSettings {
  int level = 1;  ///< zstd compression level (negative: faster, larger)
  /// A chunk is compressed and written once its records reach this many bytes (or at flush()).
  std::size_t chunkBytes = std::size_t{1} << 20;
  /// zstd worker threads compressing a chunk in parallel (0: in the writer's compression
  /// thread alone). A chunk is split into jobs of about chunkBytes / workers.
  int workers = 0;
  /// false: the caller compresses every chunk at `level` itself (the writer before its
  /// compression thread; kept for the benchmark's comparison).
  bool compressionThread = true;
  /// false: every chunk is stored uncompressed (no CPU spent on compression at all).
  bool compress = true;
};

/// Writes one recording (docs/recording.md): the header at create(), then chunks as records
/// come, then the index and trailer at close(). Every chunk is written whole with write(), so a
/// reader may follow the file while it grows. Not thread-safe: one thread calls it; the writer
/// compresses and writes chunks in a thread of its own, in order. A full chunk goes to that
/// thread; when it is still busy with an earlier one, the caller stores the chunk
/// uncompressed (a zstd frame of raw blocks, which any zstd decoder reads:
/// a copy and a checksum), so the recording never waits for compression, only for the disk
/// (at most 4 chunks queued).
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
  /// Compresses and writes the records added since the last chunk (nothing when none), and
  /// waits until every chunk is in the file.
  Status flush();
  /// Flushes, writes the index and the trailer, closes the file. Called by the destructor when
  /// not called before (errors then go unreported).
  Status close();

  /// Bytes of messages added so far; bytes in the file once flushed or closed.
  std::uint64_t messageBytes() const { return messageBytes_; }
  std::uint64_t fileBytes() const;
  /// Chunks the caller stored uncompressed because the compression thread was behind; chunks
  /// written in all (both final once flushed or closed).
  std::uint64_t storedChunks() const { return storedChunks_; }
  std::uint64_t chunksWritten() const;

 private:
  struct Compressor;
  /// A chunk on its way to the file: its records, or its frame once compressed.
  struct Chunk {
    ChunkInfo info;
    std::vector<std::byte> raw;
    std::vector<std::byte> frame;  ///< chunk header + zstd frame (its header alone if stored)
    bool stored = false;           ///< `raw` goes into the file as the frame's raw blocks
    std::vector<std::byte> blockHeaders;  ///< stored: 3 bytes per raw block
    std::array<std::byte, 4> checksum{};  ///< stored: the frame's checksum
  };
  RecordingWriter() = default;
  Status writeAll(std::span<const std::byte> bytes);
  /// Compresses `chunk.raw` with `zstd` into `chunk.frame`.
  Status compress(Compressor& zstd, Chunk& chunk) const;
  /// Makes `chunk` a stored one: a zstd frame of raw blocks around its records.
  void store(Chunk& chunk) const;
  /// Writes the chunk (its pieces with writev() when stored).
  Status writeChunk(const Chunk& chunk);
  /// Writes the chunk header before a frame of `frameBytes` and lets go of the records.
  void finishFrame(Chunk& chunk, std::size_t frameBytes) const;
  /// Hands the chunk being filled to the compression thread (or compresses it here, fast).
  Status submit();
  /// The compression thread: compresses and writes queued chunks in order.
  void compressAndWrite();
  /// Waits until the queue is empty and the thread idle; its first error.
  Status drain();

  std::unique_ptr<Compressor> zstd_;  // at `level`: the thread's (the caller's without it)
  std::string path_;
  int fd_ = -1;
  WriterSettings settings_;
  std::uint32_t connectionCount_ = 0;
  std::uint64_t messageBytes_ = 0;
  std::uint64_t storedChunks_ = 0;
  Chunk filling_;  // records of the chunk being filled

  mutable std::mutex mutex_;         // guards what follows
  std::condition_variable changed_;  // the queue, busy_ or stop_ changed
  std::deque<Chunk> queue_;
  bool busy_ = false;  // the thread holds a chunk out of the queue
  bool stop_ = false;
  Status error_;  // the thread's first error

  std::vector<ChunkInfo> index_;  // appended by the thread
  std::thread thread_;
  std::atomic<std::uint64_t> offset_ = 0;  // bytes written (by create(), the thread, close())
};

}  // namespace vrflow::record
