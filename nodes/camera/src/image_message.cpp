#include "vrflow/camera/image_message.hpp"

#include <cstring>
#include <string>
#include <vector>

#include "raw_form.hpp"
#include "vrflow/message/packed.hpp"

namespace vrflow::camera {

namespace {
constexpr char kMagic[4] = {'V', 'X', 'I', '1'};
constexpr std::uint32_t kVersion = 1;
}  // namespace

void addImage(msg::MessageBuilder& builder, std::uint64_t resourceId, const cv::Mat& image) {
  const std::size_t rowBytes = static_cast<std::size_t>(image.cols) * image.elemSize();
  std::vector<std::byte> body(kImageHeaderSize + rowBytes * static_cast<std::size_t>(image.rows));
  std::memcpy(body.data(), kMagic, 4);
  msg::storeRaw(body.data() + 4, kVersion);
  msg::storeRaw(body.data() + 8, std::int32_t{image.cols});
  msg::storeRaw(body.data() + 12, std::int32_t{image.rows});
  msg::storeRaw(body.data() + 16, std::int32_t{image.type()});
  msg::storeRaw(body.data() + 20, static_cast<std::uint32_t>(rowBytes));
  for (int row = 0; row < image.rows; ++row)
    std::memcpy(body.data() + kImageHeaderSize + rowBytes * static_cast<std::size_t>(row),
                image.ptr(row), rowBytes);
  builder.addRawResource(resourceId, true, body);
}

Result<cv::Mat> readImage(const msg::ResourceView& resource) {
  const auto checked = rawFormBody(resource, kMagic, kVersion, kImageHeaderSize, "image");
  if (!checked) return checked.error();
  const auto body = *checked;
  const std::string what = "resource " + std::to_string(resource.id()) + ": ";
  const auto width = msg::loadRaw<std::int32_t>(body.data() + 8);
  const auto height = msg::loadRaw<std::int32_t>(body.data() + 12);
  const auto type = msg::loadRaw<std::int32_t>(body.data() + 16);
  const auto rowBytes = msg::loadRaw<std::uint32_t>(body.data() + 20);
  if (width <= 0 || height <= 0 || width > 65536 || height > 65536 || CV_MAT_DEPTH(type) != CV_8U ||
      type < 0 || type > CV_8UC4)
    return Error{what + "image of impossible size " + std::to_string(width) + "x" +
                 std::to_string(height) + " or type " + std::to_string(type) +
                 " (8-bit, 1 to 4 channels)"};
  const std::size_t expectedRow = static_cast<std::size_t>(width) * CV_ELEM_SIZE(type);
  if (rowBytes != expectedRow ||
      body.size() - kImageHeaderSize != expectedRow * static_cast<std::size_t>(height))
    return Error{what + "image holds " + std::to_string(body.size() - kImageHeaderSize) +
                 " bytes, its header says " + std::to_string(height) + " rows of " +
                 std::to_string(expectedRow)};
  // A view over the message: the pixels are read in place, never written.
  auto* pixels = const_cast<std::byte*>(body.data() + kImageHeaderSize);  // NOLINT: read-only view
  return cv::Mat(height, width, type, pixels, rowBytes);
}

Result<std::vector<cv::Mat>> readImages(const msg::MessageView& message) {
  std::vector<cv::Mat> images;
  for (const auto chunk : message) {
    const auto resource = chunk.asResource();
    if (!resource) continue;
    auto image = readImage(*resource);
    if (!image) return image.error();
    images.push_back(*image);
  }
  return images;
}

std::optional<std::int64_t> captureTimeNs(const msg::MessageView& message) {
  return int64Stamp(message, kCaptureStamp);
}

}  // namespace vrflow::camera
