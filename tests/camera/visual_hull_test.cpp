// The visual hull against the exact voxelisation of the synthetic user, and its mesh.
#include "vrflow/camera/visual_hull.hpp"

#include <gtest/gtest.h>

#include "vrflow/camera/distance_field.hpp"
#include "vrflow/camera/hull_mesh.hpp"
#include "vrflow/camera/synthetic_scene.hpp"

namespace vrflow::camera {
namespace {

struct Rig {
  std::vector<CameraCalibration> cameras;
  std::vector<MaskView> views;

  Rig(int count, const SyntheticUser& user) : cameras(cameraRing(count)) {
    for (const CameraCalibration& camera : cameras)
      views.push_back({&camera, user.renderMask(camera)});
  }
};

double hullIoU(int cameras, int cells) {
  const SyntheticUser user(standingPose());
  const Rig rig(cameras, user);
  auto hull = carveVisualHull(rig.views, userVolume(cells));
  EXPECT_TRUE(hull) << hull.error().message;
  return intersectionOverUnion(*hull, user.voxelize(userVolume(cells)));
}

TEST(VisualHull, FiveCamerasGiveIoUOfAtLeastNinetyPercent) {
  const double iou = hullIoU(5, 128);
  EXPECT_GE(iou, 0.9);
  RecordProperty("iou_5_cameras", std::to_string(iou));
}

TEST(VisualHull, FewerCamerasGiveALooserHull) {
  const double iou3 = hullIoU(3, 96), iou4 = hullIoU(4, 96), iou5 = hullIoU(5, 96);
  std::printf("visual hull IoU at 96^3: 3 cameras %.3f, 4 cameras %.3f, 5 cameras %.3f\n", iou3,
              iou4, iou5);
  RecordProperty("iou_3_cameras", std::to_string(iou3));
  RecordProperty("iou_4_cameras", std::to_string(iou4));
  EXPECT_LT(iou3, iou5);
  EXPECT_GT(iou3, 0.5);
}

TEST(VisualHull, ContainsTheUser) {
  // A visual hull is a superset of the object: every voxel of the user is kept.
  const SyntheticUser user(standingPose());
  const Rig rig(5, user);
  auto hull = carveVisualHull(rig.views, userVolume(96));
  ASSERT_TRUE(hull);
  const VoxelGrid exact = user.voxelize(userVolume(96));
  std::size_t missed = 0;
  for (std::size_t n = 0; n < exact.occupied.size(); ++n)
    missed += exact.occupied[n] && !hull->occupied[n];
  // Only voxels whose centre projects onto a silhouette's edge pixel may be lost to rounding.
  EXPECT_LT(static_cast<double>(missed), 0.01 * static_cast<double>(exact.countOccupied()));
}

TEST(VisualHull, HierarchicalCarvingEqualsTheStraightforwardOne) {
  const SyntheticUser user(standingPose());
  const Rig rig(5, user);
  CarveStats stats;
  auto fast = carveVisualHull(rig.views, userVolume(96), &stats);
  auto slow = carveVisualHullBaseline(rig.views, userVolume(96));
  ASSERT_TRUE(fast && slow);
  std::size_t differ = 0;
  for (std::size_t n = 0; n < fast->occupied.size(); ++n)
    differ += fast->occupied[n] != slow->occupied[n];
  // cv::projectPoints and the carver's projection may round a centre on a pixel's edge apart.
  EXPECT_LE(differ, fast->countOccupied() / 1000);
  EXPECT_GT(stats.blocksDecided, 0u);
  EXPECT_LT(stats.voxelsTested, fast->occupied.size() / 4);
}

TEST(VisualHull, SlabsCarvedApartGatherIntoTheWholeHull) {
  const SyntheticUser user(standingPose());
  const Rig rig(4, user);
  const GridSpec spec = userVolume(64);
  auto whole = carveVisualHull(rig.views, spec);
  ASSERT_TRUE(whole);
  VoxelGrid gathered(spec);
  for (auto [begin, end] : {std::pair{0, 21}, {21, 40}, {40, 64}})
    ASSERT_TRUE(carveVisualHull(rig.views, begin, end, gathered));
  EXPECT_EQ(gathered.occupied, whole->occupied);
}

TEST(VisualHull, MasksOfTheWrongSizeOrABadSlabAreErrors) {
  const SyntheticUser user(standingPose());
  Rig rig(3, user);
  rig.views[1].mask = cv::Mat(240, 320, CV_8UC1, cv::Scalar(0));
  auto hull = carveVisualHull(rig.views, userVolume(32));
  ASSERT_FALSE(hull);
  EXPECT_EQ(hull.error().message,
            "camera 1: mask of 320x240 (CV_8UC1) where the calibration says 640x480 CV_8UC1");
  VoxelGrid grid(userVolume(32));
  const Rig good(3, user);
  const auto status = carveVisualHull(good.views, 30, 40, grid);
  ASSERT_FALSE(status);
  EXPECT_EQ(status.error().message,
            "slab [30, 40) is not a non-empty range of the grid's 32 z layers");
}

TEST(VisualHull, MoreThanSixtyFourCamerasAreAnError) {
  const std::vector<CameraCalibration> cameras = cameraRing(65, {32, 24});
  std::vector<MaskView> views;
  for (const CameraCalibration& camera : cameras)
    views.push_back({&camera, cv::Mat(24, 32, CV_8UC1, cv::Scalar(255))});
  auto hull = carveVisualHull(views, userVolume(8));
  ASSERT_FALSE(hull);
  EXPECT_EQ(hull.error().message, "65 cameras: the visual hull takes at most 64");
  views.pop_back();
  EXPECT_TRUE(carveVisualHull(views, userVolume(8)));
}

TEST(HullMesh, IsClosedAndEnclosesTheVoxelVolume) {
  const SyntheticUser user(standingPose());
  const Rig rig(5, user);
  auto hull = carveVisualHull(rig.views, userVolume(128));
  ASSERT_TRUE(hull);
  const TriangleMesh mesh = meshHull(*hull, signedDistanceField(*hull));
  ASSERT_GT(mesh.triangles.size(), 1000u);
  EXPECT_TRUE(mesh.isClosed());
  const double voxels =
      static_cast<double>(hull->countOccupied()) * std::pow(hull->spec.voxelSize, 3);
  const double relative = (mesh.volume() - voxels) / voxels;
  std::printf("mesh volume %.5f m^3, voxels %.5f m^3 (%+.2f%%)\n", mesh.volume(), voxels,
              100 * relative);
  RecordProperty("mesh_volume_relative_error", std::to_string(relative));
  EXPECT_LT(std::abs(relative), 0.05);
}

TEST(HullMesh, SphereMeshMatchesTheSphere) {
  const GridSpec spec = GridSpec::cube({-1, -1, -1}, 2.0, 64);
  VoxelGrid grid(spec);
  for (int k = 0; k < spec.nz; ++k)
    for (int j = 0; j < spec.ny; ++j)
      for (int i = 0; i < spec.nx; ++i)
        grid.occupied[spec.index(i, j, k)] = cv::norm(spec.centre(i, j, k)) <= 0.6 ? 1 : 0;
  const TriangleMesh mesh = meshHull(grid, signedDistanceField(grid));
  EXPECT_TRUE(mesh.isClosed());
  const double sphere = 4.0 / 3.0 * CV_PI * 0.6 * 0.6 * 0.6;
  EXPECT_NEAR(mesh.volume(), sphere, 0.03 * sphere);
  for (const cv::Vec3f& v : mesh.vertices) EXPECT_NEAR(cv::norm(v), 0.6, spec.voxelSize);
}

TEST(HullMesh, AGridFullToItsBorderIsClosedByTheBorder) {
  VoxelGrid grid(GridSpec{{0, 0, 0}, 0.1, 3, 4, 5});
  std::fill(grid.occupied.begin(), grid.occupied.end(), std::uint8_t{1});
  const TriangleMesh mesh = meshHull(grid, signedDistanceField(grid));
  EXPECT_TRUE(mesh.isClosed());
  EXPECT_NEAR(mesh.volume(), 0.3 * 0.4 * 0.5, 0.3 * 0.4 * 0.5 * 0.1);
}

}  // namespace
}  // namespace vrflow::camera
