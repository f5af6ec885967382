#include "vrflow/record/writer.hpp"

#include <fcntl.h>
#include <limits.h>
#include <sys/file.h>
#include <sys/uio.h>
#include <unistd.h>
#include <xxhash.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <limits>

namespace vrflow::record {

struct RecordingWriter::Compressor {
  ZSTD_CCtx* context = ZSTD_createCCtx();
  ~Compressor() { ZSTD_freeCCtx(context); }
};

namespace {
// Chunks queued for the compression thread beyond which the caller waits (for the disk).
constexpr std::size_t kMaxQueuedChunks = 4;
// A stored zstd frame (RFC 8878): magic, a descriptor for a single segment with an 8-byte
// content size and a checksum, raw blocks of at most 128 KiB, the XXH64 checksum's low half.
constexpr std::uint32_t kZstdMagic = 0xFD2FB528;
constexpr std::uint8_t kStoredFrameDescriptor = 0xE4;  // FCS 8 bytes, single segment, checksum
constexpr std::size_t kStoredFrameHeaderBytes = 4 + 1 + 8;
constexpr std::size_t kRawBlockBytes = std::size_t{128} << 10;
}  // namespace

namespace {

std::size_t padTo8(std::size_t n) {
  return (n + 7) & ~std::size_t{7};
}

std::uint64_t wallNs() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

}  // namespace

Result<std::unique_ptr<RecordingWriter>> RecordingWriter::create(
    const std::string& path, const std::vector<RecordedConnection>& connections,
    WriterSettings settings, std::uint64_t startNs) {
  // The connection table: a count, then module, port and data type of each (u16 length + bytes).
  std::vector<std::byte> table(4);
  putU32(table.data(), static_cast<std::uint32_t>(connections.size()));
  for (const auto& c : connections) {
    for (const std::string* text : {&c.module, &c.port, &c.data}) {
      if (text->empty() || text->size() > std::numeric_limits<std::uint16_t>::max()) {
        return makeError("cannot record connection '" + c.name() +
                         "': a name is empty or too long");
      }
      const std::size_t at = table.size();
      table.resize(at + 2 + text->size());
      putU16(table.data() + at, static_cast<std::uint16_t>(text->size()));
      std::memcpy(table.data() + at + 2, text->data(), text->size());
    }
  }
  std::unique_ptr<RecordingWriter> writer(new RecordingWriter());
  writer->path_ = path;
  writer->settings_ = settings;
  writer->connectionCount_ = static_cast<std::uint32_t>(connections.size());
  writer->zstd_ = std::make_unique<Compressor>();
  if (writer->zstd_->context == nullptr) {
    return makeError("zstd: cannot create a context");
  }
  ZSTD_CCtx_setParameter(writer->zstd_->context, ZSTD_c_compressionLevel, settings.level);
  ZSTD_CCtx_setParameter(writer->zstd_->context, ZSTD_c_checksumFlag, 1);
  if (settings.workers > 0) {
    const std::size_t nbWorkers =
        ZSTD_CCtx_setParameter(writer->zstd_->context, ZSTD_c_nbWorkers, settings.workers);
    if (ZSTD_isError(nbWorkers) != 0) {
      return makeError(std::string("zstd: no worker threads: ") + ZSTD_getErrorName(nbWorkers));
    }
    const auto job = std::max<std::size_t>(
        settings.chunkBytes / static_cast<std::size_t>(settings.workers), std::size_t{512} << 10);
    ZSTD_CCtx_setParameter(writer->zstd_->context, ZSTD_c_jobSize, static_cast<int>(job));
  }
  writer->fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (writer->fd_ < 0) return makeError("cannot write '" + path + "': " + std::strerror(errno));
  // Held until close(): tells a reader that the file is being written (beingWritten()).
  (void)::flock(writer->fd_, LOCK_EX | LOCK_NB);
  std::vector<std::byte> header(kFileHeaderBytes);
  std::memcpy(header.data(), kFileMagic.data(), kFileMagic.size());
  putU32(header.data() + 8, kFormatVersion);
  putU32(header.data() + 12, static_cast<std::uint32_t>(table.size()));
  putU64(header.data() + 16, startNs != 0 ? startNs : wallNs());
  header.insert(header.end(), table.begin(), table.end());
  if (auto status = writer->writeAll(header); !status) return status.error();
  writer->thread_ = std::thread([w = writer.get()] { w->compressAndWrite(); });
  return writer;
}

RecordingWriter::~RecordingWriter() {
  if (fd_ >= 0) (void)close();
}

std::uint64_t RecordingWriter::fileBytes() const {
  return offset_.load();
}

std::uint64_t RecordingWriter::chunksWritten() const {
  std::lock_guard lock(mutex_);
  return index_.size();
}

Status RecordingWriter::writeAll(std::span<const std::byte> bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return makeError("cannot write '" + path_ + "': " + std::strerror(errno));
    bytes = bytes.subspan(static_cast<std::size_t>(n));
    offset_ += static_cast<std::uint64_t>(n);  // the thread, or create() and close() alone
  }
  return {};
}

Status RecordingWriter::add(std::uint32_t connection, std::uint64_t iteration,
                            std::uint64_t arrivalNs, std::span<const std::byte> message) {
  if (fd_ < 0) return makeError("'" + path_ + "' is closed");
  if (connection >= connectionCount_) {
    return makeError("no recorded connection has index " + std::to_string(connection));
  }
  if (message.size() >= kMaxChunkBytes) return makeError("a message of 4 GiB or more");
  auto& raw = filling_.raw;
  const std::size_t at = raw.size();
  raw.resize(at + kRecordHeaderBytes + padTo8(message.size()));
  std::byte* record = raw.data() + at;
  putU32(record, connection);
  putU32(record + 4, 0);
  putU64(record + 8, iteration);
  putU64(record + 16, arrivalNs);
  putU64(record + 24, message.size());
  std::memcpy(record + kRecordHeaderBytes, message.data(), message.size());
  std::memset(record + kRecordHeaderBytes + message.size(), 0,
              padTo8(message.size()) - message.size());
  auto& info = filling_.info;
  if (info.records == 0) info.firstArrivalNs = arrivalNs;
  info.lastArrivalNs = arrivalNs;
  ++info.records;
  messageBytes_ += message.size();
  if (raw.size() >= settings_.chunkBytes) return submit();
  return {};
}

Status RecordingWriter::compress(Compressor& zstd, Chunk& chunk) const {
  chunk.frame.resize(kChunkHeaderBytes + ZSTD_compressBound(chunk.raw.size()));
  const std::size_t size =
      ZSTD_compress2(zstd.context, chunk.frame.data() + kChunkHeaderBytes,
                     chunk.frame.size() - kChunkHeaderBytes, chunk.raw.data(), chunk.raw.size());
  if (ZSTD_isError(size) != 0) {
    return makeError("zstd: cannot compress a chunk of '" + path_ +
                     "': " + ZSTD_getErrorName(size));
  }
  chunk.frame.resize(kChunkHeaderBytes + size);
  finishFrame(chunk, size);
  return {};
}

void RecordingWriter::store(Chunk& chunk) const {
  // The records stay where they are: the thread writes them between the block headers with
  // writev(), so storing costs the checksum alone.
  const std::size_t size = chunk.raw.size();
  const std::size_t blocks = (size + kRawBlockBytes - 1) / kRawBlockBytes;
  const std::size_t frameBytes = kStoredFrameHeaderBytes + 3 * blocks + size + 4;
  chunk.frame.resize(kChunkHeaderBytes + kStoredFrameHeaderBytes);
  std::byte* at = chunk.frame.data() + kChunkHeaderBytes;
  putU32(at, kZstdMagic);
  at[4] = std::byte{kStoredFrameDescriptor};
  putU64(at + 5, size);
  chunk.blockHeaders.resize(3 * blocks);
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t n = std::min(kRawBlockBytes, size - b * kRawBlockBytes);
    // Block header, 3 bytes little-endian: last flag, type 0 (raw), size.
    const auto header = static_cast<std::uint32_t>((n << 3) | (b + 1 == blocks ? 1u : 0u));
    for (std::size_t k = 0; k < 3; ++k)
      chunk.blockHeaders[3 * b + k] = static_cast<std::byte>((header >> (8 * k)) & 0xFF);
  }
  putU32(chunk.checksum.data(),
         static_cast<std::uint32_t>(XXH64(chunk.raw.data(), size, 0) & 0xFFFFFFFFu));
  chunk.stored = true;
  finishFrame(chunk, frameBytes);
}

void RecordingWriter::finishFrame(Chunk& chunk, std::size_t frameBytes) const {
  chunk.info.rawBytes = chunk.raw.size();
  chunk.info.compressedBytes = frameBytes;
  std::byte* header = chunk.frame.data();
  putU32(header, kChunkMagic);
  putU32(header + 4, chunk.info.records);
  putU64(header + 8, frameBytes);
  putU64(header + 16, chunk.raw.size());
  putU64(header + 24, chunk.info.firstArrivalNs);
  putU64(header + 32, chunk.info.lastArrivalNs);
  if (!chunk.stored) chunk.raw = {};
}

Status RecordingWriter::writeChunk(const Chunk& chunk) {
  if (!chunk.stored) return writeAll(chunk.frame);
  std::vector<iovec> pieces;
  const auto piece = [&](const std::byte* data, std::size_t n) {
    pieces.push_back({const_cast<std::byte*>(data), n});  // NOLINT: writev only reads them
  };
  piece(chunk.frame.data(), chunk.frame.size());
  for (std::size_t b = 0, done = 0; done < chunk.raw.size(); ++b) {
    const std::size_t n = std::min(kRawBlockBytes, chunk.raw.size() - done);
    piece(chunk.blockHeaders.data() + 3 * b, 3);
    piece(chunk.raw.data() + done, n);
    done += n;
  }
  piece(chunk.checksum.data(), chunk.checksum.size());
  std::size_t first = 0;
  while (first < pieces.size()) {
    const int count = static_cast<int>(std::min<std::size_t>(pieces.size() - first, IOV_MAX));
    const ssize_t n = ::writev(fd_, pieces.data() + first, count);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return makeError("cannot write '" + path_ + "': " + std::strerror(errno));
    offset_ += static_cast<std::uint64_t>(n);
    // Skip what was written, part of a piece included.
    for (auto left = static_cast<std::size_t>(n); left > 0;) {
      iovec& p = pieces[first];
      const std::size_t used = std::min(left, p.iov_len);
      p.iov_base = static_cast<std::byte*>(p.iov_base) + used;
      p.iov_len -= used;
      left -= used;
      if (p.iov_len == 0) ++first;
    }
    while (first < pieces.size() && pieces[first].iov_len == 0) ++first;
  }
  return {};
}

Status RecordingWriter::submit() {
  if (filling_.info.records == 0) return {};
  Chunk chunk = std::move(filling_);
  filling_ = {};
  bool fast = false;
  {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return queue_.size() < kMaxQueuedChunks || !error_; });
    if (!error_) return error_;
    // The thread is still compressing an earlier chunk: this one would wait for it.
    fast = busy_ || !queue_.empty() || !settings_.compress;
  }
  if (!settings_.compressionThread) {
    if (auto status = compress(*zstd_, chunk); !status) return status;
  } else if (fast) {
    store(chunk);
    ++storedChunks_;
  }
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(chunk));
  }
  changed_.notify_all();
  return {};
}

void RecordingWriter::compressAndWrite() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return stop_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopped, nothing left
    Chunk chunk = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    const bool ok = static_cast<bool>(error_);  // after an error, chunks are dropped
    lock.unlock();
    Status status;
    if (ok && chunk.frame.empty()) status = compress(*zstd_, chunk);
    if (ok && status) {
      chunk.info.offset = offset_.load();
      status = writeChunk(chunk);
    }
    lock.lock();
    busy_ = false;
    if (ok && status) index_.push_back(chunk.info);
    if (ok && !status) error_ = std::move(status);
    changed_.notify_all();
  }
}

Status RecordingWriter::drain() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return queue_.empty() && !busy_; });
  return error_;
}

Status RecordingWriter::flush() {
  if (fd_ < 0) return makeError("'" + path_ + "' is closed");
  if (auto status = submit(); !status) return status;
  return drain();
}

Status RecordingWriter::close() {
  if (fd_ < 0) return {};
  Status status = flush();
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (status) {
    std::vector<std::byte> tail(kIndexHeaderBytes + index_.size() * kIndexEntryBytes +
                                kTrailerBytes);
    putU32(tail.data(), kIndexMagic);
    putU32(tail.data() + 4, static_cast<std::uint32_t>(index_.size()));
    std::byte* entry = tail.data() + kIndexHeaderBytes;
    for (const ChunkInfo& c : index_) {
      putU64(entry, c.offset);
      putU64(entry + 8, c.firstArrivalNs);
      putU64(entry + 16, c.lastArrivalNs);
      putU64(entry + 24, c.rawBytes);
      putU64(entry + 32, c.compressedBytes);
      putU32(entry + 40, c.records);
      putU32(entry + 44, 0);
      entry += kIndexEntryBytes;
    }
    putU64(entry, offset_.load());
    std::memcpy(entry + 8, kTrailerMagic.data(), kTrailerMagic.size());
    status = writeAll(tail);
  }
  if (::close(fd_) != 0 && status) {
    status = makeError("cannot write '" + path_ + "': " + std::strerror(errno));
  }
  fd_ = -1;
  return status;
}

}  // namespace vrflow::record
