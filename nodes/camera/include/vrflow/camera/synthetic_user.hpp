#pragma once
// The synthetic user, ground truth of the camera chain: an articulated body of capsules (head,
// torso, upper and lower arms, hands) between joints posed by a keyframe file (format in
// nodes/camera/README.md), its exact occupancy of a voxel grid, its analytic signed distance and
// its exact silhouette in a calibrated camera.

#include <array>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/camera/calibration.hpp"
#include "vrflow/camera/voxel_grid.hpp"

namespace vrflow::camera {

/// A segment [a, b] swept by a sphere of `radius` (metres, world frame).
struct Capsule {
  cv::Vec3d a, b;
  double radius = 0;

  /// Signed distance of `p` to the capsule's surface (negative inside).
  double signedDistance(const cv::Vec3d& p) const;
};

/// The joints a pose gives, in a keyframe file's spelling.
inline constexpr std::array<const char*, 11> kUserJoints = {
    "head",   "neck",       "pelvis",  "shoulder_l", "elbow_l", "wrist_l",
    "hand_l", "shoulder_r", "elbow_r", "wrist_r",    "hand_r"};

/// Joint positions (world frame, metres), in kUserJoints' order.
using UserPose = std::array<cv::Vec3d, kUserJoints.size()>;

/// The user's body at one pose: its capsules.
class SyntheticUser {
 public:
  explicit SyntheticUser(const UserPose& pose);

  const std::vector<Capsule>& capsules() const { return capsules_; }
  /// Analytic signed distance (m) to the body's surface, negative inside.
  double signedDistance(const cv::Vec3d& p) const;
  /// Exact occupancy: a voxel is occupied when its centre is inside a capsule.
  VoxelGrid voxelize(const GridSpec& spec) const;
  /// Exact silhouette as `camera` sees it (255 where the ray through a pixel's centre meets the
  /// body, through the camera's distortion), CV_8UC1 of the camera's image size.
  cv::Mat renderMask(const CameraCalibration& camera) const;

 private:
  std::vector<Capsule> capsules_;
};

/// A standing pose with the arms reaching forward and out: the default ground truth.
UserPose standingPose();

/// Keyframes of the user's joints, interpolated linearly in time and held before the first and
/// after the last.
class KeyframeTrack {
 public:
  /// Reads a keyframe file; one error naming file:line for the first mistake.
  static Result<KeyframeTrack> load(const std::string& path);
  /// The same from text (`name` stands for the file in messages).
  static Result<KeyframeTrack> parse(const std::string& text, const std::string& name);

  /// The pose at time `t` (seconds).
  UserPose poseAt(double t) const;
  double startTime() const { return keys_.begin()->first; }
  double endTime() const { return keys_.rbegin()->first; }

 private:
  std::map<double, UserPose> keys_;
};

}  // namespace vrflow::camera
