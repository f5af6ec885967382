#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include "vrflow/base/result.hpp"

// The frames daemons exchange over TCP (docs/transport.md has the layout and the rules).
namespace vrflow::net {

/// "VRF1", little-endian: the first four bytes of every frame.
inline constexpr uint32_t kFrameMagic = 0x31465256;
inline constexpr std::size_t kFrameHeaderBytes = 16;
inline constexpr uint32_t kProtocolVersion = 1;
inline constexpr std::size_t kNonceBytes = 32;
inline constexpr std::size_t kMacBytes = 32;
/// Default largest message frame: 256 MiB.
inline constexpr uint32_t kDefaultMaxFrameBytes = 256u << 20;

/// What a frame carries.
enum class FrameType : uint8_t {
  Hello = 1,      ///< connector -> listener: version, host indices, nonce
  Challenge = 2,  ///< listener -> connector: nonce and the listener's proof
  Auth = 3,       ///< connector -> listener: the connector's proof
  Message = 4,    ///< one message of a connection (channel), its bytes as in shared memory
  Close = 5,      ///< the connection (channel) will carry nothing more
  Credit = 6,     ///< the receiver took `count` messages of a channel off the wire
  Heartbeat = 7,  ///< sender's steady clock (ns); keeps a silent link known alive
  Bye = 8,        ///< the sender ends the link on purpose
};

/// The 16 bytes in front of every payload.
struct FrameHeader {
  FrameType type = FrameType::Heartbeat;
  uint32_t channel = 0;  ///< index of the connection in the application file
  uint32_t length = 0;   ///< payload bytes
};

/// Writes a header into 16 bytes.
void encodeHeader(const FrameHeader& header, std::byte* out);
/// The exact payload size a control frame must have (0 for Message, which varies).
std::size_t controlPayloadBytes(FrameType type);
/// "hello", "message", ...; "unknown" for anything else.
const char* frameTypeName(FrameType type);

/// Incremental, allocation-aware frame parser. Bytes come in through feed() (or, inside a
/// large message payload, straight into directTarget()); each complete frame is handed to the
/// deliver callback. Any violation is returned as an error, after which the reader must not be
/// used again (the link is closed). It never reads beyond what it was given.
class FrameReader {
 public:
  /// Gives the buffer for a message payload of `length` bytes (in shared memory); an empty span
  /// means the receiver cannot take it (an error).
  using Allocate = std::function<std::span<std::byte>(const FrameHeader&)>;
  /// A complete frame; for Message frames `payload` is the span Allocate gave.
  using Deliver = std::function<Status(const FrameHeader&, std::span<const std::byte> payload)>;

  FrameReader(uint32_t maxFrameBytes, Allocate allocate, Deliver deliver)
      : maxFrameBytes_(maxFrameBytes),
        allocate_(std::move(allocate)),
        deliver_(std::move(deliver)) {}

  /// Until authenticated, only Hello/Challenge/Auth frames are accepted.
  void setAuthenticated(bool authenticated) { authenticated_ = authenticated; }
  /// Parses `data`, delivering every frame it completes.
  Status feed(std::span<const std::byte> data);
  /// Inside a message payload: the part still to be filled, for a direct read; else empty.
  std::span<std::byte> directTarget();
  /// Records that `bytes` were written into directTarget() (delivers the frame when full).
  Status advanceDirect(std::size_t bytes);
  /// True between frames (no partial frame held).
  bool idle() const { return headerFill_ == 0 && !inPayload_; }

 private:
  Status startPayload();
  Status finishPayload();

  uint32_t maxFrameBytes_;
  Allocate allocate_;
  Deliver deliver_;
  bool authenticated_ = false;
  std::array<std::byte, kFrameHeaderBytes> header_{};
  std::size_t headerFill_ = 0;
  FrameHeader current_{};
  bool inPayload_ = false;
  std::span<std::byte> target_;  ///< message payload in shared memory, or control_ below
  std::size_t filled_ = 0;
  std::array<std::byte, 64> control_{};
};

}  // namespace vrflow::net
