#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "vrflow/net/frame.hpp"
#include "vrflow/net/transport.hpp"

// The challenge-response between daemons (docs/transport.md, "Authentication").
namespace vrflow::net::detail {

/// HMAC-SHA256(secret, label | u32 connector | u32 listener | connector nonce | listener nonce).
std::array<std::byte, kMacBytes> proof(const Secret& secret, const char* label, uint32_t connector,
                                       uint32_t listener, const std::byte* nonceC,
                                       const std::byte* nonceL);

/// Constant-time comparison of two proofs.
bool sameMac(const std::byte* a, const std::byte* b);

/// Little-endian u32 into 4 bytes.
void putU32(std::byte* out, uint32_t v);

}  // namespace vrflow::net::detail
