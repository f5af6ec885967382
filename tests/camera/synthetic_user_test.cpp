// The synthetic user: keyframes, exact occupancy, analytic distance and exact silhouettes.
#include "vrflow/camera/synthetic_user.hpp"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <sstream>

#include "process_helpers.hpp"
#include "user_keys.hpp"
#include "vrflow/camera/synthetic_scene.hpp"

namespace vrflow::camera {
namespace {

using vrflow::testing::TempDir;

TEST(Keyframes, PosesAreInterpolatedLinearlyAndHeldAtTheEnds) {
  UserPose raised = standingPose();
  raised[6] += cv::Vec3d(0, 0.4, 0);  // hand_l up by 40 cm
  auto track = KeyframeTrack::parse(
      "# a wave\n" + keyText(0, standingPose()) + "\n" + keyText(2, raised), "wave.keys");
  ASSERT_TRUE(track) << track.error().message;
  EXPECT_DOUBLE_EQ(track->poseAt(1)[6][1], standingPose()[6][1] + 0.2);
  EXPECT_DOUBLE_EQ(track->poseAt(-5)[6][1], standingPose()[6][1]);
  EXPECT_DOUBLE_EQ(track->poseAt(7)[6][1], raised[6][1]);
  EXPECT_DOUBLE_EQ(track->endTime(), 2.0);
}

TEST(Keyframes, AnEmptyFileIsOneClearError) {
  TempDir dir;
  const std::string path = dir.write("empty.keys", "# nothing yet\n\n");
  auto track = KeyframeTrack::load(path);
  ASSERT_FALSE(track);
  EXPECT_EQ(track.error().message, path + ": no keyframe (expected lines 'TIME JOINT X Y Z')");
}

TEST(Keyframes, AMissingFileIsOneClearError) {
  auto track = KeyframeTrack::load("/nonexistent/user.keys");
  ASSERT_FALSE(track);
  EXPECT_EQ(track.error().message, "/nonexistent/user.keys: cannot read the keyframe file");
}

TEST(Keyframes, MistakesNameTheFileAndLine) {
  auto unknown = KeyframeTrack::parse(keyText(0, standingPose()) + "1 knee 0 0.5 0\n", "u.keys");
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().message,
            "u.keys:12: unknown joint 'knee' (head, neck, pelvis, shoulder_l/r, elbow_l/r, "
            "wrist_l/r, hand_l/r)");
  auto shortLine = KeyframeTrack::parse("0 head 0 1.6\n", "s.keys");
  ASSERT_FALSE(shortLine);
  EXPECT_EQ(shortLine.error().message,
            "s.keys:1: expected 'TIME JOINT X Y Z' (seconds, joint name, metres)");
  auto incomplete = KeyframeTrack::parse(keyText(0, standingPose()) + "1 head 0 1.7 0\n", "i.keys");
  ASSERT_FALSE(incomplete);
  EXPECT_EQ(incomplete.error().message, "i.keys:12: the key at time 1.000000 lacks joint 'neck'");
}

TEST(SyntheticUser, OccupancyIsTheSignOfTheAnalyticDistance) {
  const SyntheticUser user(standingPose());
  const GridSpec spec = userVolume(48);
  const VoxelGrid grid = user.voxelize(spec);
  std::size_t inside = 0;
  for (int k = 0; k < spec.nz; ++k)
    for (int j = 0; j < spec.ny; ++j)
      for (int i = 0; i < spec.nx; ++i) {
        const bool occupied = grid.occupied[spec.index(i, j, k)];
        EXPECT_EQ(occupied, user.signedDistance(spec.centre(i, j, k)) <= 0);
        inside += occupied;
      }
  // The capsules' volume, roughly (overlaps counted once): torso and head dominate.
  const double volume = static_cast<double>(inside) * std::pow(spec.voxelSize, 3);
  EXPECT_GT(volume, 0.05);
  EXPECT_LT(volume, 0.08);
  // The volume's border is outside the user: the whole body fits in the grid.
  for (int j = 0; j < spec.ny; ++j)
    for (int i = 0; i < spec.nx; ++i) {
      EXPECT_EQ(grid.occupied[spec.index(i, j, 0)], 0);
      EXPECT_EQ(grid.occupied[spec.index(i, j, spec.nz - 1)], 0);
    }
}

TEST(SyntheticUser, SilhouetteContainsTheProjectionOfEveryInnerPoint) {
  const SyntheticUser user(standingPose());
  CameraCalibration camera = cameraRing(5)[1];
  camera.distortion = (cv::Mat_<double>(1, 5) << -0.05, 0.01, 0, 0, 0);
  const cv::Mat mask = user.renderMask(camera);
  cv::RNG rng(7);
  std::vector<cv::Point3d> points;
  std::vector<bool> inside;
  while (points.size() < 40000) {
    const cv::Vec3d p(rng.uniform(-0.7, 0.7), rng.uniform(0.45, 1.85), rng.uniform(-0.5, 0.9));
    const double d = user.signedDistance(p);
    if (std::abs(d) < 0.01) continue;  // away from the surface: pixels are ~5 mm there
    points.emplace_back(p);
    inside.push_back(d < 0);
  }
  cv::Vec3d rvec;
  cv::Rodrigues(camera.rotation, rvec);
  std::vector<cv::Point2d> pixels;
  cv::projectPoints(points, rvec, camera.translation, camera.cameraMatrix, camera.distortion,
                    pixels);
  int checked = 0;
  for (std::size_t n = 0; n < points.size(); ++n) {
    const cv::Point pixel(static_cast<int>(std::lround(pixels[n].x)),
                          static_cast<int>(std::lround(pixels[n].y)));
    if (!cv::Rect({}, mask.size()).contains(pixel)) continue;
    if (inside[n]) {
      EXPECT_EQ(mask.at<std::uint8_t>(pixel), 255);
      ++checked;
    }
  }
  EXPECT_GT(checked, 500);
  // The body covers a plausible part of the view (about 1.1 m tall at 2.5 m).
  EXPECT_GT(cv::countNonZero(mask), 5000);
  EXPECT_LT(cv::countNonZero(mask), mask.size().area() / 4);
}

}  // namespace
}  // namespace vrflow::camera
