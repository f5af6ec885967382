// The signed distance field: exact against brute force, within a voxel of analytic distances.
#include "vrflow/camera/distance_field.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "vrflow/camera/synthetic_scene.hpp"
#include "vrflow/camera/synthetic_user.hpp"
#include "vrflow/camera/user_surface.hpp"

namespace vrflow::camera {
namespace {

// The brute-force squared distance from every voxel to the nearest one of occupancy `target`.
std::vector<float> bruteForce(const VoxelGrid& grid, std::uint8_t target) {
  const GridSpec& s = grid.spec;
  std::vector<float> d(s.count(), kNoVoxel);
  for (int k = 0; k < s.nz; ++k)
    for (int j = 0; j < s.ny; ++j)
      for (int i = 0; i < s.nx; ++i)
        for (int c = 0; c < s.nz; ++c)
          for (int b = 0; b < s.ny; ++b)
            for (int a = 0; a < s.nx; ++a)
              if (grid.occupied[s.index(a, b, c)] == target)
                d[s.index(i, j, k)] = std::min(
                    d[s.index(i, j, k)],
                    static_cast<float>((a - i) * (a - i) + (b - j) * (b - j) + (c - k) * (c - k)));
  return d;
}

TEST(DistanceField, SquaredDistancesEqualBruteForceOnRandomGrids) {
  cv::RNG rng(21);
  for (int trial = 0; trial < 40; ++trial) {
    VoxelGrid grid(
        GridSpec{{0, 0, 0}, 1.0, rng.uniform(1, 9), rng.uniform(1, 9), rng.uniform(1, 9)});
    const double density = rng.uniform(0.0, 1.0) < 0.2 ? 0.01 : rng.uniform(0.05, 0.9);
    for (auto& v : grid.occupied) v = rng.uniform(0.0, 1.0) < density ? 1 : 0;
    for (std::uint8_t target : {std::uint8_t{0}, std::uint8_t{1}})
      EXPECT_EQ(squaredDistanceTo(grid, target), bruteForce(grid, target))
          << "trial " << trial << ", " << grid.spec.nx << "x" << grid.spec.ny << "x"
          << grid.spec.nz;
  }
}

TEST(DistanceField, SignedFieldEqualsBruteForceOnRandomGrids) {
  cv::RNG rng(22);
  for (int trial = 0; trial < 40; ++trial) {
    const GridSpec s{{0, 0, 0}, 0.5, rng.uniform(1, 10), rng.uniform(1, 10), rng.uniform(1, 10)};
    VoxelGrid grid(s);
    // A blob away from the border or anywhere: both the bounding box and the border cases.
    const double density = rng.uniform(0.05, 0.6);
    const bool blob = trial % 2 == 0;
    for (int k = 0; k < s.nz; ++k)
      for (int j = 0; j < s.ny; ++j)
        for (int i = 0; i < s.nx; ++i) {
          const bool interior =
              i > 1 && j > 1 && k > 1 && i < s.nx - 2 && j < s.ny - 2 && k < s.nz - 2;
          grid.occupied[s.index(i, j, k)] = (!blob || interior) && rng.uniform(0.0, 1.0) < density;
        }
    const std::vector<float> toInside = bruteForce(grid, 1), toOutside = bruteForce(grid, 0);
    std::vector<float> expected(s.count());
    for (int k = 0; k < s.nz; ++k)
      for (int j = 0; j < s.ny; ++j)
        for (int i = 0; i < s.nx; ++i) {
          const std::size_t n = s.index(i, j, k);
          const int border = 1 + std::min({i, j, k, s.nx - 1 - i, s.ny - 1 - j, s.nz - 1 - k});
          expected[n] =
              grid.occupied[n]
                  ? -(std::min(std::sqrt(toOutside[n]), static_cast<float>(border)) - 0.5f) * 0.5f
                  : (toInside[n] >= kNoVoxel ? kNoVoxel : (std::sqrt(toInside[n]) - 0.5f) * 0.5f);
        }
    EXPECT_EQ(signedDistanceField(grid), expected) << "trial " << trial;
  }
}

// The largest |sdf - exact| over the grid, in voxels, for a solid of analytic signed distance.
// With a finite `band`, the banded field: within the band against the analytic distance, and
// where it holds the clamp, the analytic distance must be at least the band less a voxel.
template <typename Distance>
double worstErrorInVoxels(const GridSpec& spec, Distance exact,
                          double band = std::numeric_limits<double>::infinity()) {
  VoxelGrid grid(spec);
  for (int k = 0; k < spec.nz; ++k)
    for (int j = 0; j < spec.ny; ++j)
      for (int i = 0; i < spec.nx; ++i)
        grid.occupied[spec.index(i, j, k)] = exact(spec.centre(i, j, k)) <= 0 ? 1 : 0;
  const std::vector<float> sdf =
      std::isinf(band) ? signedDistanceField(grid) : signedDistanceFieldInBand(grid, band, 2);
  const auto clamp = static_cast<float>(band);
  double worst = 0;
  for (int k = 0; k < spec.nz; ++k)
    for (int j = 0; j < spec.ny; ++j)
      for (int i = 0; i < spec.nx; ++i) {
        const float d = sdf[spec.index(i, j, k)];
        const double truth = exact(spec.centre(i, j, k));
        worst = std::max(
            worst, d == clamp ? std::max(band - truth, 0.0) - spec.voxelSize : std::abs(d - truth));
      }
  return worst / spec.voxelSize;
}

TEST(DistanceField, SphereDistanceIsWithinOneVoxel) {
  const GridSpec spec = GridSpec::cube({-1, -1, -1}, 2.0, 64);
  const double worst = worstErrorInVoxels(
      spec, [](const cv::Vec3d& p) { return cv::norm(p - cv::Vec3d(0.05, -0.1, 0.02)) - 0.55; });
  EXPECT_LE(worst, 1.0);
  RecordProperty("sphere_worst_error_voxels", std::to_string(worst));
}

TEST(DistanceField, CapsuleDistanceIsWithinOneVoxel) {
  const Capsule capsule{{-0.5, -0.3, 0.1}, {0.45, 0.35, -0.2}, 0.22};
  const double worst =
      worstErrorInVoxels(GridSpec::cube({-1, -1, -1}, 2.0, 64),
                         [&](const cv::Vec3d& p) { return capsule.signedDistance(p); });
  EXPECT_LE(worst, 1.0);
  RecordProperty("capsule_worst_error_voxels", std::to_string(worst));
}

TEST(DistanceField, AnEmptyGridIsFarEverywhere) {
  const VoxelGrid grid(GridSpec{{0, 0, 0}, 0.1, 4, 5, 6});
  for (float d : signedDistanceField(grid)) EXPECT_EQ(d, kNoVoxel);
  for (float d : signedDistanceFieldInBand(grid, 0.2)) EXPECT_EQ(d, kNoVoxel);
}

// Whether two fields hold the same bits.
bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// The user's exact voxelisation in the benchmark's volume.
VoxelGrid userGrid(int cells) {
  return SyntheticUser(standingPose()).voxelize(userVolume(cells));
}

TEST(BandedDistanceField, EqualsTheWholeFieldWithinTheBandAndTheClampBeyond) {
  for (int cells : {48, 64}) {
    const VoxelGrid grid = userGrid(cells);
    const std::vector<float> full = signedDistanceField(grid);
    for (double band : {0.0, 0.5 * grid.spec.voxelSize, 0.05, 0.1, 0.23, 0.6}) {
      const std::vector<float> banded = signedDistanceFieldInBand(grid, band, 2);
      ASSERT_EQ(banded.size(), full.size());
      const auto clamp = static_cast<float>(band);
      std::size_t inBand = 0, clamped = 0, wrong = 0;
      for (std::size_t n = 0; n < full.size(); ++n) {
        const float expected = std::min(full[n], clamp);
        wrong += std::memcmp(&banded[n], &expected, sizeof(float)) != 0;
        (full[n] > clamp ? clamped : inBand) += 1;
      }
      EXPECT_EQ(wrong, 0u) << cells << "^3, band " << band;
      EXPECT_GT(clamped, 0u) << "the band must leave voxels beyond it";
      if (band > grid.spec.voxelSize) {
        EXPECT_GT(inBand, grid.countOccupied()) << "the band must hold outside voxels too";
      }
    }
  }
}

TEST(BandedDistanceField, EqualsBruteForceClampedOnRandomGrids) {
  cv::RNG rng(23);
  for (int trial = 0; trial < 30; ++trial) {
    VoxelGrid grid(
        GridSpec{{0, 0, 0}, 0.5, rng.uniform(1, 12), rng.uniform(1, 12), rng.uniform(1, 12)});
    const double density = rng.uniform(0.0, 0.1);
    for (auto& v : grid.occupied) v = rng.uniform(0.0, 1.0) < density ? 1 : 0;
    const double band = rng.uniform(0.0, 3.0);
    std::vector<float> expected = signedDistanceField(grid);
    if (grid.countOccupied() > 0)
      for (float& d : expected) d = std::min(d, static_cast<float>(band));
    EXPECT_TRUE(sameBits(signedDistanceFieldInBand(grid, band), expected))
        << "trial " << trial << ", band " << band;
  }
}

TEST(BandedDistanceField, DoesNotDependOnTheThreadCount) {
  const VoxelGrid grid = userGrid(64);
  const std::vector<float> one = signedDistanceFieldInBand(grid, 0.2, 1);
  for (int threads : {2, 3, 8})
    EXPECT_TRUE(sameBits(signedDistanceFieldInBand(grid, 0.2, threads), one)) << threads;
}

TEST(BandedDistanceField, AnInfiniteBandIsTheWholeField) {
  const VoxelGrid grid = userGrid(48);
  EXPECT_TRUE(sameBits(signedDistanceFieldInBand(grid, std::numeric_limits<double>::infinity()),
                       signedDistanceField(grid)));
}

TEST(BandedDistanceField, SphereAndCapsuleAreWithinOneVoxelInsideTheBand) {
  const GridSpec spec = GridSpec::cube({-1, -1, -1}, 2.0, 64);
  const double sphere = worstErrorInVoxels(
      spec, [](const cv::Vec3d& p) { return cv::norm(p - cv::Vec3d(0.05, -0.1, 0.02)) - 0.55; },
      0.2);
  const Capsule capsule{{-0.5, -0.3, 0.1}, {0.45, 0.35, -0.2}, 0.22};
  const double capsuleWorst = worstErrorInVoxels(
      spec, [&](const cv::Vec3d& p) { return capsule.signedDistance(p); }, 0.2);
  EXPECT_LE(sphere, 1.0);
  EXPECT_LE(capsuleWorst, 1.0);
}

// The user as the interactors read it (UserSurface) from a field over the user's grid.
UserSurface surfaceOf(const GridSpec& s, std::vector<float> sdf) {
  UserSurface u;
  u.dims = {static_cast<std::uint32_t>(s.nx), static_cast<std::uint32_t>(s.ny),
            static_cast<std::uint32_t>(s.nz)};
  const cv::Vec3d first = s.centre(0, 0, 0);
  u.origin = {first[0], first[1], first[2]};
  u.spacing = s.voxelSize;
  u.sdf = std::move(sdf);
  return u;
}

TEST(BandedDistanceField, ReadersWithinTheReachSeeTheWholeFieldsDistanceAndNormal) {
  // The example's largest reach: a 0.15 m ball's centre plus the rigid interactor's 0.04 m.
  const double reach = 0.19;
  const VoxelGrid grid = userGrid(64);
  const GridSpec& s = grid.spec;
  const UserSurface full = surfaceOf(s, signedDistanceField(grid));
  const UserSurface banded = surfaceOf(s, signedDistanceFieldInBand(grid, fieldBandFor(reach, s)));
  cv::RNG rng(24);
  int near = 0;
  for (int n = 0; n < 200000; ++n) {
    const msg::Vec3 p{rng.uniform(s.origin[0] - 0.1, s.origin[0] + s.nx * s.voxelSize + 0.1),
                      rng.uniform(s.origin[1] - 0.1, s.origin[1] + s.ny * s.voxelSize + 0.1),
                      rng.uniform(s.origin[2] - 0.1, s.origin[2] + s.nz * s.voxelSize + 0.1)};
    const double d = banded.distance(p);
    if (full.distance(p) < reach) {
      ++near;
      ASSERT_EQ(d, full.distance(p)) << p[0] << " " << p[1] << " " << p[2];
      ASSERT_EQ(banded.normal(p), full.normal(p)) << p[0] << " " << p[1] << " " << p[2];
    } else {
      ASSERT_GE(d, reach) << "the band must not bring a far point within reach";
    }
  }
  EXPECT_GT(near, 1000);
}

}  // namespace
}  // namespace vrflow::camera
