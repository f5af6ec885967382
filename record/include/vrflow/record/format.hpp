#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

// The recording file format, version 1 (docs/recording.md): a header with the recorded
// connections, zstd-compressed chunks of records, an index and a trailer written at close.
// Every integer is little-endian, as in vrflow messages.
namespace vrflow::record {

/// The format version this build writes and reads.
inline constexpr std::uint32_t kFormatVersion = 1;
/// The first 8 bytes of a recording.
inline constexpr std::array<char, 8> kFileMagic = {'V', 'R', 'F', 'L', 'O', 'W', 'R', 'C'};
/// The last 8 bytes of a recording that was closed (its index is complete).
inline constexpr std::array<char, 8> kTrailerMagic = {'V', 'R', 'F', 'R', 'C', 'E', 'N', 'D'};
/// The first 4 bytes of a chunk and of the index ("CHNK", "INDX" read as little-endian u32).
inline constexpr std::uint32_t kChunkMagic = 0x4B4E4843;
inline constexpr std::uint32_t kIndexMagic = 0x58444E49;

/// Fixed part of the file header: magic, version, table size, start time.
inline constexpr std::size_t kFileHeaderBytes = 24;
/// Chunk header: magic, record count, compressed size, raw size, first and last arrival.
inline constexpr std::size_t kChunkHeaderBytes = 40;
/// Record header inside a chunk: connection, reserved, iteration, arrival, message size.
inline constexpr std::size_t kRecordHeaderBytes = 32;
/// One index entry: offset, first and last arrival, raw and compressed size, records, reserved.
inline constexpr std::size_t kIndexEntryBytes = 48;
/// Index header (magic, chunk count) and trailer (index offset, magic).
inline constexpr std::size_t kIndexHeaderBytes = 8;
inline constexpr std::size_t kTrailerBytes = 16;
/// No connection table, chunk or message may claim more than this (a corrupted length).
inline constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 32;

/// One recorded connection: the output port it leaves and the data type it carries.
struct RecordedConnection {
  std::string module;  ///< id of the module (or filter) whose output was recorded
  std::string port;    ///< its output port
  std::string data;    ///< the port's data type ("objects", "events", "any", ...)
  /// "module.port", as written in application files.
  std::string name() const { return module + "." + port; }
  bool operator==(const RecordedConnection&) const = default;
};

/// What the index says of one chunk.
struct ChunkInfo {
  std::uint64_t offset = 0;  ///< of the chunk header, from the start of the file
  std::uint64_t firstArrivalNs = 0;
  std::uint64_t lastArrivalNs = 0;
  std::uint64_t rawBytes = 0;         ///< records before compression
  std::uint64_t compressedBytes = 0;  ///< the zstd frame
  std::uint32_t records = 0;
};

/// Little-endian stores and loads into byte buffers (the only way the format is written).
void putU16(std::byte* at, std::uint16_t value);
void putU32(std::byte* at, std::uint32_t value);
void putU64(std::byte* at, std::uint64_t value);
std::uint16_t getU16(const std::byte* at);
std::uint32_t getU32(const std::byte* at);
std::uint64_t getU64(const std::byte* at);

}  // namespace vrflow::record
