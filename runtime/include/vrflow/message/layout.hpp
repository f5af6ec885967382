#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>

// The binary layout of a vrflow message, version 1. docs/message-layout.md is the reference;
// every constant here appears in its tables.

namespace vrflow::msg {

static_assert(std::endian::native == std::endian::little,
              "vrflow messages are little-endian and read in place: big-endian hosts are not "
              "supported");

/// Layout version written by this library and the only one its reader accepts.
inline constexpr std::uint16_t kLayoutVersion = 1;
/// The bytes 'V' 'R' 'F' 'M' read as a little-endian u32.
inline constexpr std::uint32_t kMagic = 0x4D465256u;
/// Every chunk starts and ends on a multiple of this many bytes from the message start.
inline constexpr std::size_t kAlignment = 8;
/// Most parameters an object type may declare (one bit each in a 64-bit mask).
inline constexpr std::size_t kMaxParams = 64;

/// Size of the fixed message header; the stamps section follows it.
inline constexpr std::size_t kMessageHeaderSize = 64;
/// Size of a chunk header; the chunk body follows it.
inline constexpr std::size_t kChunkHeaderSize = 24;
/// Size of a user stamp's header; its name and value follow it.
inline constexpr std::size_t kUserStampHeaderSize = 8;

/// Field offsets of the message header.
struct HeaderLayout {
  static constexpr std::size_t kMagic = 0;            ///< u32
  static constexpr std::size_t kVersion = 4;          ///< u16
  static constexpr std::size_t kFlags = 6;            ///< u16
  static constexpr std::size_t kTotalSize = 8;        ///< u64
  static constexpr std::size_t kStampsSize = 16;      ///< u32
  static constexpr std::size_t kChunkCount = 20;      ///< u32
  static constexpr std::size_t kIteration = 24;       ///< u64
  static constexpr std::size_t kSimTime = 32;         ///< f64
  static constexpr std::size_t kTimeStep = 40;        ///< f64
  static constexpr std::size_t kSendTimeNs = 48;      ///< u64
  static constexpr std::size_t kSourceLen = 56;       ///< u32
  static constexpr std::size_t kUserStampCount = 60;  ///< u32
};

/// Field offsets of a user stamp's header inside the stamps section.
struct UserStampLayout {
  static constexpr std::size_t kNameLen = 0;   ///< u16
  static constexpr std::size_t kType = 2;      ///< u8
  static constexpr std::size_t kPad = 3;       ///< u8, zero
  static constexpr std::size_t kValueLen = 4;  ///< u32
};

/// Field offsets of a chunk header.
struct ChunkLayout {
  static constexpr std::size_t kSize = 0;       ///< u32: whole chunk, header included, padded to 8
  static constexpr std::size_t kKind = 4;       ///< u8
  static constexpr std::size_t kOp = 5;         ///< u8
  static constexpr std::size_t kSubkind = 6;    ///< u16
  static constexpr std::size_t kId = 8;         ///< u64
  static constexpr std::size_t kTypeId = 16;    ///< u32
  static constexpr std::size_t kBodySize = 20;  ///< u32: body bytes before padding
};

/// Body sizes of the fixed parts of chunk bodies.
struct BodyLayout {
  static constexpr std::size_t kObjectMask = 8;        ///< u64 mask opening an object body
  static constexpr std::size_t kParamEntryHeader = 8;  ///< u32 paramIndex, u32 len
  static constexpr std::size_t kMeshHeader = 8;        ///< u32 vertexCount, u32 indexCount
  static constexpr std::size_t kFieldHeader =
      48;                                    ///< u32 nx,ny,nz,components, f64 origin[3], spacing
  static constexpr std::size_t kForce = 80;  ///< f64 force[3], torque[3], point[3], duration
};

/// Bits of the header's flags field.
inline constexpr std::uint16_t kFlagStampsOnly = 1u << 0;
/// Every flag this version defines; a message with another bit set is rejected.
inline constexpr std::uint16_t kKnownFlags = kFlagStampsOnly;

/// What a chunk is about.
enum class ChunkKind : std::uint8_t { Object = 1, Resource = 2, Event = 3 };

/// What an object chunk does to its object.
enum class ObjectOp : std::uint8_t { Add = 1, Update = 2, Delete = 3 };

/// The shape of a resource chunk's body (the chunk's subkind).
enum class ResourceKind : std::uint16_t { Raw = 1, Mesh = 2, ScalarField = 3, VectorField = 4 };

/// Bit of a resource chunk's op: set for dynamic resources (sent on change), clear for static
/// ones (sent once per receiver).
inline constexpr std::uint8_t kResourceDynamic = 1u << 0;

/// Event kinds (an event chunk's subkind). Kinds from kFirstUserEventKind on are free for users.
enum class EventKind : std::uint16_t { Force = 1 };
inline constexpr std::uint16_t kFirstUserEventKind = 1024;

/// Type of a user stamp's value.
enum class StampType : std::uint8_t { Int64 = 1, Double = 2, String = 3 };

/// Rounds n up to a multiple of kAlignment; n must be at most UINT64_MAX - 7.
constexpr std::uint64_t padTo8(std::uint64_t n) {
  return (n + 7u) & ~std::uint64_t{7};
}

}  // namespace vrflow::msg
