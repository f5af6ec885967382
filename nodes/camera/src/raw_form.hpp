#pragma once
// What the camera package's Raw wire forms (image, contours) share: a 4-byte magic and a u32
// version at the start of the body, checked before anything else is read.
#include <cstring>
#include <span>
#include <string>

#include "vrflow/base/result.hpp"
#include "vrflow/message/chunk_views.hpp"
#include "vrflow/message/packed.hpp"

namespace vrflow::camera {

/// The body of `resource` when it is a Raw resource of at least `headerSize` bytes starting with
/// `magic` and `version`; otherwise an error "resource ID: ..." naming `what` (the form).
inline Result<std::span<const std::byte>> rawFormBody(const msg::ResourceView& resource,
                                                      const char (&magic)[4], std::uint32_t version,
                                                      std::size_t headerSize,
                                                      const std::string& what) {
  const auto body = resource.raw();
  const std::string where = "resource " + std::to_string(resource.id()) + ": ";
  if (resource.kind() != msg::ResourceKind::Raw || body.size() < headerSize ||
      std::memcmp(body.data(), magic, 4) != 0)
    return Error{where + what + " expected, no '" + std::string(magic, 4) + "' header"};
  if (const auto found = msg::loadRaw<std::uint32_t>(body.data() + 4); found != version)
    return Error{where + what + " version " + std::to_string(found) + ", this build reads " +
                 std::to_string(version)};
  return body;
}

}  // namespace vrflow::camera
