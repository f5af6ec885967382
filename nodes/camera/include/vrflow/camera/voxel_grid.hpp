#pragma once
// A regular grid of cubic voxels over the user's volume. Voxel (i, j, k) is the cube of side
// `voxelSize` whose centre is origin + (i + 1/2, j + 1/2, k + 1/2) voxelSize; storage is x
// fastest, then y, then z (a slab of z is contiguous).

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace vrflow::camera {

/// Where the grid lies and how fine it is.
struct GridSpec {
  cv::Vec3d origin{-1, 0, -1};   ///< minimum corner (m)
  double voxelSize = 2.0 / 128;  ///< edge (m)
  int nx = 128, ny = 128, nz = 128;

  std::size_t count() const { return static_cast<std::size_t>(nx) * ny * nz; }
  std::size_t index(int i, int j, int k) const {
    return (static_cast<std::size_t>(k) * ny + j) * nx + i;
  }
  cv::Vec3d centre(int i, int j, int k) const {
    return origin + cv::Vec3d(i + 0.5, j + 0.5, k + 0.5) * voxelSize;
  }
  /// A cube of `cells` voxels per edge over the box [minimum, minimum + edge]^3.
  static GridSpec cube(const cv::Vec3d& minimum, double edge, int cells) {
    return {minimum, edge / cells, cells, cells, cells};
  }
};

/// Occupancy: 1 inside the solid, 0 outside, one byte per voxel.
struct VoxelGrid {
  GridSpec spec;
  std::vector<std::uint8_t> occupied;

  explicit VoxelGrid(const GridSpec& gridSpec) : spec(gridSpec), occupied(gridSpec.count(), 0) {}
  std::size_t countOccupied() const;
};

/// Intersection over union of two occupancies of the same grid (1 when both are empty).
double intersectionOverUnion(const VoxelGrid& a, const VoxelGrid& b);

}  // namespace vrflow::camera
