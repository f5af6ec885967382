#pragma once
// An image as it travels between modules (capture -> silhouette -> hull): one dynamic Raw
// resource. Body, little-endian: "VXI1" at 0, u32 version (1) at 4, i32 width at 8, i32 height at
// 12, i32 OpenCV type (CV_8UC3 = 16 for a BGR colour image, CV_8UC1 = 0 for a mask) at 16, u32
// bytes per row (width * element size, rows packed) at 20, 8 zero bytes, then height rows from 32,
// top row first. The capture time and iteration travel beside it as the message's Int64 user
// stamps `capture-ns` and `capture-iteration` (capture_stamps.hpp).

#include <cstdint>
#include <opencv2/core.hpp>
#include <string_view>

#include "vrflow/base/result.hpp"
#include "vrflow/camera/capture_stamps.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/chunk_views.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::camera {

inline constexpr std::size_t kImageHeaderSize = 32;

/// Appends `image` (8-bit, 1 to 4 channels) as dynamic Raw resource `resourceId`.
void addImage(msg::MessageBuilder& builder, std::uint64_t resourceId, const cv::Mat& image);

/// The image a resource holds, as a cv::Mat over the message's bytes (valid while the message
/// is; clone it to keep it); an error naming what is wrong when it is not a well-formed image.
Result<cv::Mat> readImage(const msg::ResourceView& resource);

/// Every image resource of a message, in order; an error for the first malformed one.
Result<std::vector<cv::Mat>> readImages(const msg::MessageView& message);

/// The message's capture time (kCaptureStamp), nullopt when it has none.
std::optional<std::int64_t> captureTimeNs(const msg::MessageView& message);

}  // namespace vrflow::camera
