#include <sodium.h>

#include <cstdlib>
#include <cstring>

#include "handshake.hpp"
#include "vrflow/net/transport.hpp"

namespace vrflow::net {
namespace detail {

void putU32(std::byte* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out[i] = static_cast<std::byte>((v >> (8 * i)) & 0xFFu);
}

std::array<std::byte, kMacBytes> proof(const Secret& secret, const char* label, uint32_t connector,
                                       uint32_t listener, const std::byte* nonceC,
                                       const std::byte* nonceL) {
  crypto_auth_hmacsha256_state state;
  crypto_auth_hmacsha256_init(&state, secret.data(), secret.size());
  crypto_auth_hmacsha256_update(&state, reinterpret_cast<const unsigned char*>(label),
                                std::strlen(label) + 1);
  std::byte ids[8];
  putU32(ids, connector);
  putU32(ids + 4, listener);
  crypto_auth_hmacsha256_update(&state, reinterpret_cast<const unsigned char*>(ids), sizeof ids);
  crypto_auth_hmacsha256_update(&state, reinterpret_cast<const unsigned char*>(nonceC),
                                kNonceBytes);
  crypto_auth_hmacsha256_update(&state, reinterpret_cast<const unsigned char*>(nonceL),
                                kNonceBytes);
  std::array<std::byte, kMacBytes> mac{};
  crypto_auth_hmacsha256_final(&state, reinterpret_cast<unsigned char*>(mac.data()));
  return mac;
}

bool sameMac(const std::byte* a, const std::byte* b) {
  return crypto_verify_32(reinterpret_cast<const unsigned char*>(a),
                          reinterpret_cast<const unsigned char*>(b)) == 0;
}

}  // namespace detail

Secret newSecret() {
  if (sodium_init() < 0) std::abort();
  Secret secret{};
  randombytes_buf(secret.data(), secret.size());
  return secret;
}

std::string secretToHex(const Secret& secret) {
  static const char* digits = "0123456789abcdef";
  std::string text;
  for (const uint8_t b : secret) {
    text += digits[b >> 4];
    text += digits[b & 15];
  }
  return text;
}

Result<Secret> secretFromHex(const std::string& text) {
  Secret secret{};
  if (text.size() != 2 * secret.size()) return makeError("the run secret must be 64 hex digits");
  auto digit = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
  };
  for (std::size_t i = 0; i < secret.size(); ++i) {
    const int hi = digit(text[2 * i]), lo = digit(text[2 * i + 1]);
    if (hi < 0 || lo < 0) return makeError("the run secret must be 64 hex digits");
    secret[i] = static_cast<uint8_t>(hi * 16 + lo);
  }
  return secret;
}

std::string controlProof(const Secret& secret, int hostIndex, const std::string& nonce) {
  crypto_auth_hmacsha256_state state;
  crypto_auth_hmacsha256_init(&state, secret.data(), secret.size());
  const char label[] = "vrflow-control";
  crypto_auth_hmacsha256_update(&state, reinterpret_cast<const unsigned char*>(label),
                                sizeof label);
  std::byte index[4];
  detail::putU32(index, static_cast<uint32_t>(hostIndex));
  crypto_auth_hmacsha256_update(&state, reinterpret_cast<const unsigned char*>(index),
                                sizeof index);
  crypto_auth_hmacsha256_update(&state, reinterpret_cast<const unsigned char*>(nonce.data()),
                                nonce.size());
  Secret mac{};
  crypto_auth_hmacsha256_final(&state, mac.data());
  return secretToHex(mac);
}

std::string newNonceHex() {
  return secretToHex(newSecret());
}

}  // namespace vrflow::net
