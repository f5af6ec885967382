// The signed distance field: exact against brute force, within a voxel of analytic distances.
#include "vrflow/camera/distance_field.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "vrflow/camera/synthetic_user.hpp"

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
template <typename Distance>
double worstErrorInVoxels(const GridSpec& spec, Distance exact) {
  VoxelGrid grid(spec);
  for (int k = 0; k < spec.nz; ++k)
    for (int j = 0; j < spec.ny; ++j)
      for (int i = 0; i < spec.nx; ++i)
        grid.occupied[spec.index(i, j, k)] = exact(spec.centre(i, j, k)) <= 0 ? 1 : 0;
  const std::vector<float> sdf = signedDistanceField(grid);
  double worst = 0;
  for (int k = 0; k < spec.nz; ++k)
    for (int j = 0; j < spec.ny; ++j)
      for (int i = 0; i < spec.nx; ++i)
        worst = std::max(worst, std::abs(sdf[spec.index(i, j, k)] - exact(spec.centre(i, j, k))));
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
}

}  // namespace
}  // namespace vrflow::camera
