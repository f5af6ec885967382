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

/// One recorded message, read in place from a decompressed chunk.
struct RecordView {
  std::uint32_t connection = 0;        ///< index into RecordingReader::connections()
  std::uint64_t iteration = 0;         ///< the sender's iteration (the message's own stamp)
  std::uint64_t arrivalNs = 0;         ///< when the recorder received it (wall clock, ns)
  std::span<const std::byte> message;  ///< the message bytes (docs/message-layout.md)
};

/// Reads a recording (docs/recording.md). Every length is checked against the file: a
/// truncated or corrupted file is one error naming the file and the byte offset; a file of
/// another format version is refused naming both versions. Not thread-safe.
class RecordingReader {
 public:
  /// Opens `path` and reads its header and index. A file that was not closed (no trailer) is
  /// indexed by scanning its chunks. With `growing` false a chunk cut short at the end is an
  /// error (the file was truncated); with `growing` true it is a chunk still being written:
  /// it is left out, and refresh() picks it up once complete.
  static Result<std::unique_ptr<RecordingReader>> open(const std::string& path,
                                                       bool growing = false);
  /// True when a RecordingWriter has `path` open (it holds a lock on it until close()): the
  /// file is being written, and its end may be a chunk in progress rather than a truncation.
  static bool beingWritten(const std::string& path);
  ~RecordingReader();
  RecordingReader(const RecordingReader&) = delete;
  RecordingReader& operator=(const RecordingReader&) = delete;

  const std::string& path() const { return path_; }
  std::uint32_t version() const { return kFormatVersion; }
  /// The recorded connections, in the order of the header.
  const std::vector<RecordedConnection>& connections() const { return connections_; }
  /// Wall clock at the start of the recording (ns since the epoch).
  std::uint64_t startNs() const { return startNs_; }
  /// The chunks known so far, in file order.
  const std::vector<ChunkInfo>& chunks() const { return chunks_; }
  /// True when the file ends with its index and trailer (the recorder closed it).
  bool closed() const { return closed_; }
  /// Opened as a growing file (open(path, true)).
  bool growing() const { return growing_; }
  /// Bytes of the file that hold complete parts (header, chunks, index).
  std::uint64_t usedBytes() const { return scanned_; }

  /// A growing file: indexes the chunks written since open() or the last refresh(); true
  /// when it found the trailer. Nothing for a closed file.
  Status refresh();
  /// The records of chunk `i`, decompressed and checked (each message's layout too); the
  /// views stay valid until the next readChunk().
  Result<std::vector<RecordView>> readChunk(std::size_t i);

 private:
  RecordingReader() = default;
  Error errorAt(std::uint64_t offset, const std::string& what) const;
  Status readAt(std::uint64_t offset, std::span<std::byte> into) const;
  Status readHeader();
  Status readIndex();
  Status scanFrom(std::uint64_t offset);

  std::string path_;
  int fd_ = -1;
  bool growing_ = false;
  bool closed_ = false;
  std::uint64_t fileSize_ = 0;
  std::uint64_t headerEnd_ = 0;
  std::uint64_t scanned_ = 0;
  std::uint64_t startNs_ = 0;
  std::vector<RecordedConnection> connections_;
  std::vector<ChunkInfo> chunks_;
  std::vector<std::byte> compressed_;
  std::vector<std::byte> raw_;
};

}  // namespace vrflow::record
