#pragma once

#include <cstdint>
#include <string_view>

#include "vrflow/base/result.hpp"

// 64-bit object and resource ids: the high 32 bits name the host, the low 32 bits count on it.
// The counter itself lives in the host's shared memory (vrflow::ipc); this file only packs.

namespace vrflow::msg {

/// The id that names no object ("no shape", "no resource").
inline constexpr std::uint64_t kNullId = 0;

/// FNV-1a, 32 bits, of `text` (used for type ids and host names).
constexpr std::uint32_t fnv1a32(std::string_view text) {
  std::uint32_t hash = 2166136261u;
  for (const char c : text) {
    hash ^= static_cast<std::uint8_t>(c);
    hash *= 16777619u;
  }
  return hash;
}

/// Packs a host id and a per-host counter into one id.
constexpr std::uint64_t makeId(std::uint32_t hostId, std::uint32_t counter) {
  return (std::uint64_t{hostId} << 32) | counter;
}

/// The host part of an id.
constexpr std::uint32_t hostIdOf(std::uint64_t id) {
  return static_cast<std::uint32_t>(id >> 32);
}

/// The counter part of an id.
constexpr std::uint32_t counterOf(std::uint64_t id) {
  return static_cast<std::uint32_t>(id & 0xFFFFFFFFu);
}

/// The host id for a host address: a canonical dotted IPv4 address ("10.0.0.7", no leading
/// zeros) gives its 32 bits (0x0A000007); any other text (a host name, IPv6) gives FNV-1a 32 of
/// the text as written. Errors: empty text, and "0.0.0.0", which names no host.
Result<std::uint32_t> hostIdFromAddress(std::string_view address);

}  // namespace vrflow::msg
