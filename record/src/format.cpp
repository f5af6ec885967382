#include "vrflow/record/format.hpp"

#include <bit>
#include <cstring>

namespace vrflow::record {

static_assert(std::endian::native == std::endian::little, "recordings are little-endian");

void putU16(std::byte* at, std::uint16_t value) {
  std::memcpy(at, &value, sizeof value);
}
void putU32(std::byte* at, std::uint32_t value) {
  std::memcpy(at, &value, sizeof value);
}
void putU64(std::byte* at, std::uint64_t value) {
  std::memcpy(at, &value, sizeof value);
}
std::uint16_t getU16(const std::byte* at) {
  std::uint16_t value = 0;
  std::memcpy(&value, at, sizeof value);
  return value;
}
std::uint32_t getU32(const std::byte* at) {
  std::uint32_t value = 0;
  std::memcpy(&value, at, sizeof value);
  return value;
}
std::uint64_t getU64(const std::byte* at) {
  std::uint64_t value = 0;
  std::memcpy(&value, at, sizeof value);
  return value;
}

}  // namespace vrflow::record
