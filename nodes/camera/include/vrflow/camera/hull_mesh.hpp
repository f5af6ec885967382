#pragma once
// A closed triangle mesh of the hull's surface: marching tetrahedra (marching cubes on the
// Freudenthal split of every cube into six tetrahedra, which needs no case table and never leaves
// a crack) over the signed distance field, vertices placed where the field crosses zero.

#include <opencv2/core.hpp>
#include <vector>

#include "vrflow/camera/voxel_grid.hpp"

namespace vrflow::camera {

/// An indexed triangle mesh, world frame (m), triangles counter-clockwise seen from outside.
struct TriangleMesh {
  std::vector<cv::Vec3f> vertices;
  std::vector<cv::Vec3i> triangles;

  /// Enclosed volume (m^3) by the divergence theorem.
  double volume() const;
  /// True when every edge is shared by exactly two triangles, once in each direction.
  bool isClosed() const;
};

/// The surface of `grid`'s occupancy, with `sdf` (signedDistanceField(grid)) placing the vertices.
/// Voxels beyond the grid count as outside, so the mesh is closed.
TriangleMesh meshHull(const VoxelGrid& grid, const std::vector<float>& sdf);

}  // namespace vrflow::camera
