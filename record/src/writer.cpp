#include "vrflow/record/writer.hpp"

#include <fcntl.h>
#include <unistd.h>
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
  if (writer->zstd_->context == nullptr) return makeError("zstd: cannot create a context");
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
  std::vector<std::byte> header(kFileHeaderBytes);
  std::memcpy(header.data(), kFileMagic.data(), kFileMagic.size());
  putU32(header.data() + 8, kFormatVersion);
  putU32(header.data() + 12, static_cast<std::uint32_t>(table.size()));
  putU64(header.data() + 16, startNs != 0 ? startNs : wallNs());
  header.insert(header.end(), table.begin(), table.end());
  if (auto status = writer->writeAll(header); !status) return status.error();
  return writer;
}

RecordingWriter::~RecordingWriter() {
  if (fd_ >= 0) (void)close();
}

Status RecordingWriter::writeAll(std::span<const std::byte> bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return makeError("cannot write '" + path_ + "': " + std::strerror(errno));
    bytes = bytes.subspan(static_cast<std::size_t>(n));
    offset_ += static_cast<std::uint64_t>(n);
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
  const std::size_t at = raw_.size();
  raw_.resize(at + kRecordHeaderBytes + padTo8(message.size()));
  std::byte* record = raw_.data() + at;
  putU32(record, connection);
  putU32(record + 4, 0);
  putU64(record + 8, iteration);
  putU64(record + 16, arrivalNs);
  putU64(record + 24, message.size());
  std::memcpy(record + kRecordHeaderBytes, message.data(), message.size());
  std::memset(record + kRecordHeaderBytes + message.size(), 0,
              padTo8(message.size()) - message.size());
  if (pending_.records == 0) pending_.firstArrivalNs = arrivalNs;
  pending_.lastArrivalNs = arrivalNs;
  ++pending_.records;
  messageBytes_ += message.size();
  if (raw_.size() >= settings_.chunkBytes) return flush();
  return {};
}

Status RecordingWriter::flush() {
  if (fd_ < 0) return makeError("'" + path_ + "' is closed");
  if (pending_.records == 0) return {};
  compressed_.resize(kChunkHeaderBytes + ZSTD_compressBound(raw_.size()));
  const std::size_t size =
      ZSTD_compress2(zstd_->context, compressed_.data() + kChunkHeaderBytes,
                     compressed_.size() - kChunkHeaderBytes, raw_.data(), raw_.size());
  if (ZSTD_isError(size) != 0) {
    return makeError("zstd: cannot compress a chunk of '" + path_ +
                     "': " + ZSTD_getErrorName(size));
  }
  pending_.offset = offset_;
  pending_.rawBytes = raw_.size();
  pending_.compressedBytes = size;
  std::byte* header = compressed_.data();
  putU32(header, kChunkMagic);
  putU32(header + 4, pending_.records);
  putU64(header + 8, size);
  putU64(header + 16, raw_.size());
  putU64(header + 24, pending_.firstArrivalNs);
  putU64(header + 32, pending_.lastArrivalNs);
  if (auto status = writeAll({compressed_.data(), kChunkHeaderBytes + size}); !status) {
    return status;
  }
  index_.push_back(pending_);
  pending_ = {};
  raw_.clear();
  return {};
}

Status RecordingWriter::close() {
  if (fd_ < 0) return {};
  Status status = flush();
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
    putU64(entry, offset_);
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
