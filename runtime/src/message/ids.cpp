#include "vrflow/message/ids.hpp"

#include <optional>
#include <string>

namespace vrflow::msg {
namespace {

// Parses "a.b.c.d" with four decimal parts 0..255 and no leading zeros; nullopt otherwise.
std::optional<std::uint32_t> parseDottedQuad(std::string_view text) {
  std::uint32_t bits = 0;
  std::size_t pos = 0;
  for (int part = 0; part < 4; ++part) {
    if (part > 0) {
      if (pos >= text.size() || text[pos] != '.') return std::nullopt;
      ++pos;
    }
    const std::size_t start = pos;
    std::uint32_t value = 0;
    while (pos < text.size() && text[pos] >= '0' && text[pos] <= '9' && pos - start < 3) {
      value = value * 10u + static_cast<std::uint32_t>(text[pos] - '0');
      ++pos;
    }
    const std::size_t digits = pos - start;
    if (digits == 0 || value > 255 || (digits > 1 && text[start] == '0')) return std::nullopt;
    bits = (bits << 8) | value;
  }
  if (pos != text.size()) return std::nullopt;
  return bits;
}

}  // namespace

Result<std::uint32_t> hostIdFromAddress(std::string_view address) {
  if (address.empty()) return makeError("cannot derive a host id from an empty host address");
  if (const auto ipv4 = parseDottedQuad(address)) {
    if (*ipv4 == 0) {
      return makeError(
          "cannot derive a host id from '0.0.0.0': it names no host; give the "
          "host's own address");
    }
    return *ipv4;
  }
  return fnv1a32(address);
}

}  // namespace vrflow::msg
