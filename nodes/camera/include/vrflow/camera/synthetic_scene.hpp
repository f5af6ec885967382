#pragma once
// The synthetic capture rig shared by the tests and the benchmark: cameras on a ring around the
// user, the volume the hull is carved in, and colour images of a textured room with the user in it.

#include <opencv2/core.hpp>
#include <vector>

#include "vrflow/camera/calibration.hpp"
#include "vrflow/camera/synthetic_user.hpp"
#include "vrflow/camera/voxel_grid.hpp"

namespace vrflow::camera {

/// `count` cameras evenly spaced on a circle of radius 2.5 m around the user, alternately at
/// 1.6 m and 2.6 m high, all looking at the user's chest; pinhole, focal 550 px for 640x480
/// (scaled with the width).
std::vector<CameraCalibration> cameraRing(int count, cv::Size size = {640, 480});

/// The cube the user stands in (1.4 m per edge), cut in `cells` voxels per edge.
GridSpec userVolume(int cells);

/// The empty room as `camera` sees it: a fixed texture (one per seed), with sensor noise of
/// standard deviation `noise` (grey levels) drawn from `noiseSeed`. CV_8UC3.
cv::Mat renderBackground(cv::Size size, int seed, double noise, std::uint64_t noiseSeed);

/// Adds Gaussian sensor noise of standard deviation `noise` (grey levels, 0: none) drawn from
/// `noiseSeed` to a CV_8UC3 image, saturating.
void addSensorNoise(cv::Mat& image, double noise, std::uint64_t noiseSeed);
/// The room with the user: the user's exact mask filled with a textured cloth, then the noise.
cv::Mat renderUserImage(const SyntheticUser& user, const CameraCalibration& camera, int seed,
                        double noise, std::uint64_t noiseSeed);

}  // namespace vrflow::camera
