#include "vrflow/message/digest.hpp"

// The state lives on the stack (no allocation per digest); the header and the library come
// from the same libxxhash package, so its layout matches.
#define XXH_STATIC_LINKING_ONLY
#include <xxhash.h>

#include <array>
#include <cstring>

namespace vrflow::msg {

std::uint64_t digest(const MessageView& message) {
  const auto bytes = message.bytes();
  // Small messages: hash a copy in one shot (streaming costs more than copying them).
  constexpr std::size_t kCopyLimit = 1024;
  if (bytes.size() <= kCopyLimit) {
    // NOLINTNEXTLINE(cppcoreguidelines-pro-type-member-init): filled by the memcpy below
    std::array<std::byte, kCopyLimit> copy;
    std::memcpy(copy.data(), bytes.data(), bytes.size());
    if (bytes.size() >= HeaderLayout::kSendTimeNs + sizeof(std::uint64_t)) {
      std::memset(copy.data() + HeaderLayout::kSendTimeNs, 0, sizeof(std::uint64_t));
    }
    return XXH3_64bits(copy.data(), bytes.size());
  }
  std::array<std::byte, kMessageHeaderSize> header{};
  std::memcpy(header.data(), bytes.data(), header.size());
  std::memset(header.data() + HeaderLayout::kSendTimeNs, 0, sizeof(std::uint64_t));
  XXH3_state_t state;
  XXH3_INITSTATE(&state);
  XXH3_64bits_reset(&state);
  XXH3_64bits_update(&state, header.data(), header.size());
  XXH3_64bits_update(&state, bytes.data() + header.size(), bytes.size() - header.size());
  return XXH3_64bits_digest(&state);
}

}  // namespace vrflow::msg
