#pragma once
// The visual hull by voxel carving: a voxel is kept when its centre projects inside the mask of
// every camera (a centre outside an image is carved). Hierarchical: the grid is visited in blocks
// from coarse to fine, and a block whose projected bounding rectangle is empty in one mask, or
// full in every mask, is decided for all its voxels at once (integral images of the masks give
// a rectangle's count in four reads); a camera whose mask is full over a block is not asked again
// inside it, and a voxel's projection is summed from per-axis terms. The masks are pinhole
// (undistorted) images: masks of cameras with lens distortion go through undistortMask first.

#include <opencv2/core.hpp>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/camera/calibration.hpp"
#include "vrflow/camera/voxel_grid.hpp"

namespace vrflow::camera {

/// One camera's view of a frame: its calibration and its silhouette mask (CV_8UC1, non-zero
/// inside) of the calibrated image size.
struct MaskView {
  const CameraCalibration* camera = nullptr;
  cv::Mat mask;
};

/// Carving statistics of one call (how much the hierarchy saved).
struct CarveStats {
  std::size_t blocksDecided = 0;  ///< blocks decided whole above the voxel level
  std::size_t voxelsTested = 0;   ///< voxels projected one by one
};

/// Carves the z slab [zBegin, zEnd) of `hull` (other slabs are left as they are), so modules can
/// each carve a slab and gather them. `threads` > 1 carves layers of 16 voxels on that many
/// oneTBB threads (the grid and the counts do not depend on it). Errors: no camera or more than
/// 64, a mask of the wrong size or type, an empty slab range outside the grid.
Status carveVisualHull(const std::vector<MaskView>& views, int zBegin, int zEnd, VoxelGrid& hull,
                       CarveStats* stats = nullptr, int threads = 1);

/// The same over the whole grid.
Result<VoxelGrid> carveVisualHull(const std::vector<MaskView>& views, const GridSpec& spec,
                                  CarveStats* stats = nullptr, int threads = 1);

/// The straightforward carving the benchmark compares against: every voxel centre projected
/// with cv::projectPoints (with the distortion) into every mask.
Result<VoxelGrid> carveVisualHullBaseline(const std::vector<MaskView>& views, const GridSpec& spec);

/// `mask` as an ideal pinhole camera of the same intrinsics would see it.
cv::Mat undistortMask(const cv::Mat& mask, const CameraCalibration& camera);

}  // namespace vrflow::camera
