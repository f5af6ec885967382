#include "vrflow/record/reader.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "vrflow/message/reader.hpp"

namespace vrflow::record {

namespace {

std::uint64_t padTo8(std::uint64_t n) {
  return (n + 7) & ~std::uint64_t{7};
}

// An upper bound of what one zstd frame (RFC 8878, section 3.1.1) decodes to, from its block
// headers alone: a raw or RLE block decodes to its stated size, a compressed one to at most
// 128 KiB (the format's block maximum). 0 for a frame whose headers do not hold together (it
// will not decode either). zstd's own ZSTD_decompressBound returns the frame header's content
// size when there is one, which is the claim this checks.
std::uint64_t decodedBound(std::span<const std::byte> frame) {
  constexpr std::uint64_t kBlockMaximum = 128 << 10;
  if (frame.size() < 5) return 0;
  // Magic, descriptor, window descriptor unless single-segment, dictionary id, content size.
  const auto descriptor = std::to_integer<unsigned>(frame[4]);
  const bool singleSegment = (descriptor & 0x20u) != 0, checksum = (descriptor & 4u) != 0;
  constexpr std::size_t kDictionaryIdBytes[4] = {0, 1, 2, 4};
  const unsigned contentSizeFlag = descriptor >> 6;
  const std::size_t contentSizeBytes =
      contentSizeFlag == 0 ? (singleSegment ? 1 : 0) : std::size_t{1} << contentSizeFlag;
  std::size_t at =
      5 + (singleSegment ? 0 : 1) + kDictionaryIdBytes[descriptor & 3u] + contentSizeBytes;
  std::uint64_t bound = 0;
  for (;;) {
    if (at + 3 > frame.size()) return 0;
    const std::uint32_t block = std::to_integer<std::uint32_t>(frame[at]) |
                                std::to_integer<std::uint32_t>(frame[at + 1]) << 8 |
                                std::to_integer<std::uint32_t>(frame[at + 2]) << 16;
    const std::uint32_t type = (block >> 1) & 3u, size = block >> 3;
    at += 3;
    if (type == 3 || (type != 2 && size > kBlockMaximum)) return 0;
    const std::size_t stored = type == 1 ? 1 : size;
    if (stored > frame.size() - at) return 0;
    at += stored;
    bound += type == 2 ? kBlockMaximum : size;
    if ((block & 1u) != 0) break;  // the last block
  }
  return at + (checksum ? 4 : 0) == frame.size() ? bound : 0;
}

}  // namespace

bool RecordingReader::beingWritten(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool locked = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);  // releases the shared lock when it was taken
  return locked;
}

Result<std::unique_ptr<RecordingReader>> RecordingReader::open(const std::string& path,
                                                               bool growing) {
  std::unique_ptr<RecordingReader> reader(new RecordingReader());
  reader->path_ = path;
  reader->growing_ = growing;
  reader->fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (reader->fd_ < 0) return makeError("cannot read '" + path + "': " + std::strerror(errno));
  struct stat info {};
  if (fstat(reader->fd_, &info) != 0 || !S_ISREG(info.st_mode)) {
    return makeError("cannot read '" + path + "': not a regular file");
  }
  reader->fileSize_ = static_cast<std::uint64_t>(info.st_size);
  if (auto status = reader->readHeader(); !status) return status.error();
  if (auto status = reader->readIndex(); !status) return status.error();
  if (!reader->closed_) {
    if (auto status = reader->scanFrom(reader->headerEnd_); !status) return status.error();
  }
  return reader;
}

RecordingReader::~RecordingReader() {
  if (fd_ >= 0) ::close(fd_);
}

Error RecordingReader::errorAt(std::uint64_t offset, const std::string& what) const {
  return Error{path_ + ": byte " + std::to_string(offset) + ": " + what};
}

Status RecordingReader::readAt(std::uint64_t offset, std::span<std::byte> into) const {
  std::size_t done = 0;
  while (done < into.size()) {
    const ssize_t n =
        ::pread(fd_, into.data() + done, into.size() - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return errorAt(offset + done, std::string("cannot read: ") + std::strerror(errno));
    if (n == 0) return errorAt(offset + done, "the file ends here (truncated)");
    done += static_cast<std::size_t>(n);
  }
  return {};
}

Status RecordingReader::readHeader() {
  std::byte fixed[kFileHeaderBytes];
  if (fileSize_ < kFileHeaderBytes) {
    return errorAt(fileSize_, "the file ends before its " + std::to_string(kFileHeaderBytes) +
                                  "-byte header (truncated, or not a vrflow recording)");
  }
  if (auto status = readAt(0, fixed); !status) return status;
  if (std::memcmp(fixed, kFileMagic.data(), kFileMagic.size()) != 0) {
    return errorAt(0, "not a vrflow recording (no 'VRFLOWRC' magic)");
  }
  const std::uint32_t version = getU32(fixed + 8);
  if (version != kFormatVersion) {
    return errorAt(8, "recording format version " + std::to_string(version) +
                          "; this vrflow reads version " + std::to_string(kFormatVersion) +
                          " only (record it again with this vrflow, or use the vrflow that "
                          "wrote it)");
  }
  const std::uint32_t tableSize = getU32(fixed + 12);
  startNs_ = getU64(fixed + 16);
  if (tableSize < 4 || kFileHeaderBytes + std::uint64_t{tableSize} > fileSize_) {
    return errorAt(12, "the connection table claims " + std::to_string(tableSize) +
                           " bytes, the file holds " + std::to_string(fileSize_) +
                           " (truncated or corrupted)");
  }
  std::vector<std::byte> table(tableSize);
  if (auto status = readAt(kFileHeaderBytes, table); !status) return status;
  const std::uint32_t count = getU32(table.data());
  std::size_t at = 4;
  for (std::uint32_t i = 0; i < count; ++i) {
    RecordedConnection c;
    for (std::string* text : {&c.module, &c.port, &c.data}) {
      if (at + 2 > table.size() || at + 2 + getU16(table.data() + at) > table.size()) {
        return errorAt(kFileHeaderBytes + at, "connection " + std::to_string(i) +
                                                  " runs past the connection table (corrupted)");
      }
      const std::uint16_t length = getU16(table.data() + at);
      text->assign(reinterpret_cast<const char*>(table.data() + at + 2), length);
      at += 2 + std::size_t{length};
    }
    connections_.push_back(std::move(c));
  }
  if (at != table.size()) {
    return errorAt(kFileHeaderBytes + at, "the connection table has " +
                                              std::to_string(table.size() - at) +
                                              " bytes past its last connection (corrupted)");
  }
  headerEnd_ = kFileHeaderBytes + tableSize;
  scanned_ = headerEnd_;
  return {};
}

Status RecordingReader::readIndex() {
  if (fileSize_ < headerEnd_ + kIndexHeaderBytes + kTrailerBytes) return {};
  std::byte trailer[kTrailerBytes];
  if (auto status = readAt(fileSize_ - kTrailerBytes, trailer); !status) return status;
  if (std::memcmp(trailer + 8, kTrailerMagic.data(), kTrailerMagic.size()) != 0) return {};
  // A trailer: the index must be whole and every chunk it names inside the file.
  const std::uint64_t indexAt = getU64(trailer);
  const std::uint64_t trailerAt = fileSize_ - kTrailerBytes;
  if (indexAt < headerEnd_ || indexAt + kIndexHeaderBytes > trailerAt) {
    return errorAt(trailerAt, "the trailer puts the index at byte " + std::to_string(indexAt) +
                                  ", outside the file (corrupted)");
  }
  std::vector<std::byte> index(trailerAt - indexAt);
  if (auto status = readAt(indexAt, index); !status) return status;
  const std::uint32_t count = getU32(index.data() + 4);
  if (getU32(index.data()) != kIndexMagic ||
      kIndexHeaderBytes + std::uint64_t{count} * kIndexEntryBytes != index.size()) {
    return errorAt(indexAt,
                   "the index is not where the trailer says, or its size does not "
                   "match its chunk count (corrupted)");
  }
  std::uint64_t expected = headerEnd_;
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::byte* entry = index.data() + kIndexHeaderBytes + std::size_t{i} * kIndexEntryBytes;
    ChunkInfo c{.offset = getU64(entry),
                .firstArrivalNs = getU64(entry + 8),
                .lastArrivalNs = getU64(entry + 16),
                .rawBytes = getU64(entry + 24),
                .compressedBytes = getU64(entry + 32),
                .records = getU32(entry + 40)};
    if (c.offset != expected || c.compressedBytes > indexAt ||
        c.offset + kChunkHeaderBytes + c.compressedBytes > indexAt) {
      return errorAt(indexAt + kIndexHeaderBytes + std::uint64_t{i} * kIndexEntryBytes,
                     "index entry " + std::to_string(i) + " names a chunk at byte " +
                         std::to_string(c.offset) + " that does not fit the file (corrupted)");
    }
    expected = c.offset + kChunkHeaderBytes + c.compressedBytes;
    chunks_.push_back(c);
  }
  if (expected != indexAt) {
    return errorAt(expected, "bytes between the last chunk and the index (corrupted)");
  }
  closed_ = true;
  scanned_ = fileSize_;
  return {};
}

Status RecordingReader::scanFrom(std::uint64_t offset) {
  while (offset < fileSize_) {
    const std::uint64_t left = fileSize_ - offset;
    std::byte header[kChunkHeaderBytes];
    if (left < kChunkHeaderBytes) {
      if (growing_) break;
      return errorAt(offset, "the file ends " + std::to_string(left) +
                                 " bytes into a chunk header (truncated)");
    }
    if (auto status = readAt(offset, header); !status) return status;
    const std::uint32_t magic = getU32(header);
    if (magic == kIndexMagic) {
      // An index without its trailer: the writer was stopped while closing.
      if (growing_) break;
      return errorAt(offset, "the index is cut short (truncated)");
    }
    if (magic != kChunkMagic) return errorAt(offset, "no chunk starts here (corrupted)");
    ChunkInfo c{.offset = offset,
                .firstArrivalNs = getU64(header + 24),
                .lastArrivalNs = getU64(header + 32),
                .rawBytes = getU64(header + 16),
                .compressedBytes = getU64(header + 8),
                .records = getU32(header + 4)};
    if (c.compressedBytes > kMaxChunkBytes || c.rawBytes > kMaxChunkBytes) {
      return errorAt(
          offset, "the chunk claims " + std::to_string(c.compressedBytes) + " bytes (corrupted)");
    }
    if (kChunkHeaderBytes + c.compressedBytes > left) {
      if (growing_) break;
      return errorAt(
          offset, "the chunk claims " + std::to_string(kChunkHeaderBytes + c.compressedBytes) +
                      " bytes, the file holds " + std::to_string(left) + " from here (truncated)");
    }
    chunks_.push_back(c);
    offset += kChunkHeaderBytes + c.compressedBytes;
    scanned_ = offset;
  }
  return {};
}

Status RecordingReader::refresh() {
  if (closed_) return {};
  struct stat info {};
  if (fstat(fd_, &info) != 0) return makeError("cannot read '" + path_ + "'");
  fileSize_ = static_cast<std::uint64_t>(info.st_size);
  // The trailer, once written, gives the complete index; else scan what was added.
  std::vector<ChunkInfo> known = std::move(chunks_);
  chunks_.clear();
  if (auto status = readIndex(); !status) return status;
  if (closed_) return {};
  chunks_ = std::move(known);
  return scanFrom(scanned_);
}

Result<std::vector<RecordView>> RecordingReader::readChunk(std::size_t i) {
  if (i >= chunks_.size()) return makeError("no chunk " + std::to_string(i));
  const ChunkInfo& c = chunks_[i];
  std::byte header[kChunkHeaderBytes];
  if (auto status = readAt(c.offset, header); !status) return status.error();
  if (getU32(header) != kChunkMagic || getU64(header + 8) != c.compressedBytes ||
      getU64(header + 16) != c.rawBytes || getU32(header + 4) != c.records) {
    return errorAt(c.offset, "the chunk header does not match the index (corrupted)");
  }
  compressed_.resize(c.compressedBytes);
  if (auto status = readAt(c.offset + kChunkHeaderBytes, compressed_); !status) {
    return status.error();
  }
  const std::uint64_t frameAt = c.offset + kChunkHeaderBytes;
  const unsigned long long content =
      ZSTD_getFrameContentSize(compressed_.data(), compressed_.size());
  if (content != c.rawBytes) {
    return errorAt(frameAt, "the zstd frame does not hold the chunk's " +
                                std::to_string(c.rawBytes) + " bytes (corrupted)");
  }
  // The sizes in the chunk and frame headers are only claims: what the frame's blocks can decode
  // to bounds the memory taken, so a damaged or hostile file claiming gigabytes in a few bytes
  // is refused before anything is allocated for it.
  const std::uint64_t bound = decodedBound(compressed_);
  if (bound < c.rawBytes) {
    return errorAt(frameAt, "the zstd frame's blocks decode to at most " + std::to_string(bound) +
                                " bytes, not the chunk's " + std::to_string(c.rawBytes) +
                                " (corrupted)");
  }
  raw_.resize(c.rawBytes);
  const std::size_t got =
      ZSTD_decompress(raw_.data(), raw_.size(), compressed_.data(), compressed_.size());
  if (ZSTD_isError(got) != 0 || got != c.rawBytes) {
    return errorAt(frameAt, std::string("the chunk does not decompress (corrupted): ") +
                                (ZSTD_isError(got) != 0 ? ZSTD_getErrorName(got) : "short"));
  }
  // Every record takes at least its header: a count the chunk cannot hold is refused before
  // anything is reserved for it.
  if (std::uint64_t{c.records} * kRecordHeaderBytes > raw_.size()) {
    return errorAt(c.offset, "the chunk claims " + std::to_string(c.records) + " records in " +
                                 std::to_string(raw_.size()) + " bytes (corrupted)");
  }
  std::vector<RecordView> records;
  records.reserve(c.records);
  std::uint64_t at = 0;
  for (std::uint32_t r = 0; r < c.records; ++r) {
    const std::string where = "record " + std::to_string(r) + " of the chunk at byte " +
                              std::to_string(c.offset) + " (raw offset " + std::to_string(at) + ")";
    if (at + kRecordHeaderBytes > raw_.size()) {
      return errorAt(c.offset, where + " runs past the chunk (corrupted)");
    }
    const std::byte* head = raw_.data() + at;
    RecordView view{.connection = getU32(head),
                    .iteration = getU64(head + 8),
                    .arrivalNs = getU64(head + 16),
                    .message = {}};
    const std::uint64_t size = getU64(head + 24);
    if (size > raw_.size() - at - kRecordHeaderBytes) {
      return errorAt(c.offset, where + " claims " + std::to_string(size) +
                                   " message bytes past the chunk (corrupted)");
    }
    if (view.connection >= connections_.size()) {
      return errorAt(c.offset, where + " names connection " + std::to_string(view.connection) +
                                   ", the header lists " + std::to_string(connections_.size()) +
                                   " (corrupted)");
    }
    view.message = {head + kRecordHeaderBytes, static_cast<std::size_t>(size)};
    if (auto parsed = msg::MessageView::parse(view.message); !parsed) {
      return errorAt(c.offset, where + ": not a valid message: " + parsed.error().message);
    }
    records.push_back(view);
    at += kRecordHeaderBytes + padTo8(size);
  }
  if (at != raw_.size()) {
    return errorAt(c.offset, "the chunk has bytes past its last record (corrupted)");
  }
  return records;
}

}  // namespace vrflow::record
