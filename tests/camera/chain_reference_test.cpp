// The fast hull, distance field and mesh give the same bits as the code they replaced (kept in
// nodes/camera/bench/reference_*.cpp) and as each other on any thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "reference_chain.hpp"
#include "vrflow/camera/distance_field.hpp"
#include "vrflow/camera/hull_mesh.hpp"
#include "vrflow/camera/synthetic_scene.hpp"
#include "vrflow/camera/visual_hull.hpp"

namespace vrflow::camera {
namespace {

struct Rig {
  std::vector<CameraCalibration> cameras;
  std::vector<MaskView> views;

  Rig(int count, const SyntheticUser& user, cv::Size size = {640, 480})
      : cameras(cameraRing(count, size)) {
    for (const CameraCalibration& camera : cameras)
      views.push_back({&camera, user.renderMask(camera)});
  }
};

// The user waving: the reference pose with the hands moved as the benchmark moves them.
UserPose wavingPose(double phase) {
  UserPose pose = standingPose();
  for (std::size_t joint : {5u, 6u}) pose[joint] += cv::Vec3d(0, 0.15 * std::sin(phase), 0.05);
  for (std::size_t joint : {9u, 10u}) pose[joint] += cv::Vec3d(0.05, -0.1 * std::sin(phase), 0);
  return pose;
}

bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

bool sameMesh(const TriangleMesh& a, const TriangleMesh& b) {
  return a.vertices == b.vertices && a.triangles == b.triangles;
}

TEST(FastChain, HullEqualsTheReferenceCarvingBitForBit) {
  for (int cameras : {3, 4, 5})
    for (double phase : {0.0, 1.5, 3.0, 4.5}) {
      const SyntheticUser user(wavingPose(phase));
      const Rig rig(cameras, user);
      for (int cells : {64, 128}) {
        auto hull = carveVisualHull(rig.views, userVolume(cells));
        ASSERT_TRUE(hull);
        VoxelGrid expected(userVolume(cells));
        reference::carveVisualHull(rig.views, expected);
        EXPECT_EQ(hull->occupied, expected.occupied)
            << cameras << " cameras, phase " << phase << ", " << cells << "^3";
      }
    }
}

TEST(FastChain, DistanceFieldAndMeshOfTheUsersHullEqualTheReferenceBitForBit) {
  for (double phase : {0.0, 2.0, 4.0}) {
    const SyntheticUser user(wavingPose(phase));
    const Rig rig(5, user);
    auto hull = carveVisualHull(rig.views, userVolume(128));
    ASSERT_TRUE(hull);
    const std::vector<float> sdf = signedDistanceField(*hull);
    EXPECT_TRUE(sameBits(sdf, reference::signedDistanceField(*hull))) << "phase " << phase;
    EXPECT_TRUE(sameMesh(meshHull(*hull, sdf), reference::meshHull(*hull, sdf)))
        << "phase " << phase;
  }
}

// The field the benchmark's chain computes: the reference's within the band the example's
// interactors read, the band beyond; the mesh from it is the reference's mesh.
TEST(FastChain, BandedFieldOfTheUsersHullIsTheReferenceClampedAndGivesTheSameMesh) {
  for (double phase : {0.5, 3.5}) {
    const SyntheticUser user(wavingPose(phase));
    const Rig rig(5, user);
    auto hull = carveVisualHull(rig.views, userVolume(128));
    ASSERT_TRUE(hull);
    const double band = fieldBandFor(0.19, hull->spec);
    std::vector<float> expected = reference::signedDistanceField(*hull);
    const TriangleMesh expectedMesh = reference::meshHull(*hull, expected);
    for (float& d : expected) d = std::min(d, static_cast<float>(band));
    const std::vector<float> banded = signedDistanceFieldInBand(*hull, band, 2);
    EXPECT_TRUE(sameBits(banded, expected)) << "phase " << phase;
    EXPECT_TRUE(sameMesh(meshHull(*hull, banded), expectedMesh)) << "phase " << phase;
  }
}

TEST(FastChain, DistanceFieldAndMeshOfRandomGridsEqualTheReference) {
  cv::RNG rng(2127);
  for (int trial = 0; trial < 60; ++trial) {
    const GridSpec s{
        {0.1, -0.2, 0.3}, 0.05, rng.uniform(1, 24), rng.uniform(1, 24), rng.uniform(1, 24)};
    VoxelGrid grid(s);
    const double density = rng.uniform(0.0, 1.0) < 0.2 ? 0.01 : rng.uniform(0.05, 0.95);
    for (auto& v : grid.occupied) v = rng.uniform(0.0, 1.0) < density ? 1 : 0;
    for (std::uint8_t target : {std::uint8_t{0}, std::uint8_t{1}})
      EXPECT_TRUE(
          sameBits(squaredDistanceTo(grid, target), reference::squaredDistanceTo(grid, target)))
          << "trial " << trial;
    const std::vector<float> sdf = signedDistanceField(grid);
    EXPECT_TRUE(sameBits(sdf, reference::signedDistanceField(grid))) << "trial " << trial;
    EXPECT_TRUE(sameMesh(meshHull(grid, sdf), reference::meshHull(grid, sdf))) << "trial " << trial;
  }
}

TEST(FastChain, AnyThreadCountGivesTheSameBitsAsOneThread) {
  const SyntheticUser user(wavingPose(1.0));
  const Rig rig(5, user);
  CarveStats oneStats;
  auto one = carveVisualHull(rig.views, userVolume(96), &oneStats, 1);
  ASSERT_TRUE(one);
  const std::vector<float> sdf = signedDistanceField(*one, 1);
  const TriangleMesh mesh = meshHull(*one, sdf);
  for (int threads : {2, 3, 8}) {
    CarveStats stats;
    auto hull = carveVisualHull(rig.views, userVolume(96), &stats, threads);
    ASSERT_TRUE(hull);
    EXPECT_EQ(hull->occupied, one->occupied) << threads << " threads";
    EXPECT_EQ(stats.blocksDecided, oneStats.blocksDecided) << threads << " threads";
    EXPECT_EQ(stats.voxelsTested, oneStats.voxelsTested) << threads << " threads";
    EXPECT_TRUE(sameBits(signedDistanceField(*one, threads), sdf)) << threads << " threads";
    EXPECT_TRUE(sameBits(squaredDistanceTo(*one, 0, threads), squaredDistanceTo(*one, 0, 1)))
        << threads << " threads";
  }
  EXPECT_TRUE(mesh.isClosed());
}

}  // namespace
}  // namespace vrflow::camera
