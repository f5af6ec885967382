#include "vrflow/camera/contour_message.hpp"

#include <cstring>
#include <string>

#include "raw_form.hpp"
#include "vrflow/message/packed.hpp"

namespace vrflow::camera {

namespace {
constexpr char kMagic[4] = {'V', 'X', 'C', '1'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderSize = 16;
}  // namespace

void addContours(msg::MessageBuilder& builder, std::uint64_t resourceId,
                 const std::vector<std::vector<cv::Point>>& contours) {
  std::size_t size = kHeaderSize;
  for (const auto& contour : contours) size += 4 + 8 * contour.size();
  std::vector<std::byte> body(size);
  std::memcpy(body.data(), kMagic, 4);
  msg::storeRaw(body.data() + 4, kVersion);
  msg::storeRaw(body.data() + 8, static_cast<std::uint32_t>(contours.size()));
  std::byte* at = body.data() + kHeaderSize;
  for (const auto& contour : contours) {
    msg::storeRaw(at, static_cast<std::uint32_t>(contour.size()));
    at += 4;
    for (const auto& point : contour) {
      msg::storeRaw(at, std::int32_t{point.x});
      msg::storeRaw(at + 4, std::int32_t{point.y});
      at += 8;
    }
  }
  builder.addRawResource(resourceId, true, body);
}

Result<std::vector<std::vector<cv::Point>>> readContours(const msg::ResourceView& resource) {
  const auto checked = rawFormBody(resource, kMagic, kVersion, kHeaderSize, "contours");
  if (!checked) return checked.error();
  const auto body = *checked;
  const std::string what = "resource " + std::to_string(resource.id()) + ": ";
  const auto count = msg::loadRaw<std::uint32_t>(body.data() + 8);
  std::vector<std::vector<cv::Point>> contours;
  std::size_t at = kHeaderSize;
  for (std::uint32_t n = 0; n < count; ++n) {
    if (body.size() - at < 4) return Error{what + "contours cut short"};
    const auto points = msg::loadRaw<std::uint32_t>(body.data() + at);
    at += 4;
    if ((body.size() - at) / 8 < points) return Error{what + "contours cut short"};
    auto& contour = contours.emplace_back(points);
    for (auto& point : contour) {
      point = {msg::loadRaw<std::int32_t>(body.data() + at),
               msg::loadRaw<std::int32_t>(body.data() + at + 4)};
      at += 8;
    }
  }
  if (at != body.size()) return Error{what + "bytes after the last contour"};
  return contours;
}

}  // namespace vrflow::camera
