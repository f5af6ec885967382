// libFuzzer target: the TCP frame reader of the daemons (runtime/src/net/frame.cpp) on arbitrary
// bytes, as a hostile peer would send them. Byte 0 picks the authentication state and how the
// stream is cut into reads; the rest is the stream. Beyond "no crash, no sanitizer report", it
// checks what the reader promises: it never asks for a message buffer over the limit, every
// delivered frame has the length its header announced, and after an error it is never fed again.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "vrflow/net/frame.hpp"

namespace {

void check(bool condition) {
  if (!condition) __builtin_trap();
}

constexpr uint32_t kLimit = 1 << 16;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const uint8_t mode = data[0];
  std::span<const std::byte> stream(reinterpret_cast<const std::byte*>(data + 1), size - 1);
  std::vector<std::byte> storage;
  uint32_t announced = 0;
  std::size_t delivered = 0;
  vrflow::net::FrameReader reader(
      kLimit,
      [&](const vrflow::net::FrameHeader& header) {
        check(header.length <= kLimit && header.length > 0);
        announced = header.length;
        storage.assign(header.length, std::byte{0});
        return std::span<std::byte>(storage);
      },
      [&](const vrflow::net::FrameHeader& header,
          std::span<const std::byte> payload) -> vrflow::Status {
        check(payload.size() == header.length);
        if (header.type == vrflow::net::FrameType::Message) check(payload.size() == announced);
        ++delivered;
        return {};
      });
  reader.setAuthenticated((mode & 1) != 0);
  const std::size_t cut = 1 + (mode >> 1);  // read sizes from 1 to 128 bytes
  std::size_t offset = 0;
  while (offset < stream.size()) {
    vrflow::Status status;
    auto direct = reader.directTarget();
    const std::size_t take = std::min(cut, stream.size() - offset);
    if (!direct.empty() && (mode & 2) != 0) {
      // As the daemon does for large payloads: read straight into the target.
      const std::size_t n = std::min(take, direct.size());
      std::memcpy(direct.data(), stream.data() + offset, n);
      status = reader.advanceDirect(n);
      offset += n;
    } else {
      status = reader.feed(stream.subspan(offset, take));
      offset += take;
    }
    if (!status) return 0;  // the link is closed: nothing more is read
  }
  (void)delivered;
  return 0;
}
