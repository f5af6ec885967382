#pragma once
// A silhouette's outer contours as they travel between modules: one dynamic Raw resource.
// Body, little-endian: "VXC1" at 0, u32 version (1) at 4, u32 contour count at 8, 4 zero bytes,
// then per contour a u32 point count followed by that many (i32 x, i32 y) pixel positions.

#include <opencv2/core.hpp>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/chunk_views.hpp"

namespace vrflow::camera {

/// Appends `contours` as dynamic Raw resource `resourceId`.
void addContours(msg::MessageBuilder& builder, std::uint64_t resourceId,
                 const std::vector<std::vector<cv::Point>>& contours);

/// The contours a resource holds; an error naming what is wrong when it is malformed.
Result<std::vector<std::vector<cv::Point>>> readContours(const msg::ResourceView& resource);

}  // namespace vrflow::camera
