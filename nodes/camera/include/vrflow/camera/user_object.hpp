#pragma once
// The user object the user animator publishes (type `user`, builtin_types.hpp): a kinematic
// solid of infinite mass, re-described every frame from the voxel model: its mesh (marching
// tetrahedra), its signed distance field (exact EDT, negative inside) and its surface velocity,
// three dynamic resources the object names, sent before its chunk in the same message.

#include <cstdint>
#include <limits>
#include <vector>

#include "vrflow/camera/hull_mesh.hpp"
#include "vrflow/camera/voxel_grid.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/values.hpp"

namespace vrflow::camera {

/// The user at one frame.
struct UserFrame {
  GridSpec spec;
  std::size_t voxels = 0;       ///< occupied voxels
  std::vector<float> sdf;       ///< signedDistanceField of the voxel model
  TriangleMesh mesh;            ///< meshHull of it
  std::vector<float> velocity;  ///< surfaceVelocity, three per voxel (empty: not sent)
  msg::Vec3 position{};         ///< centroid of the occupied voxels (the grid's centre if none)
  msg::Aabb bounds;             ///< box of the occupied voxels' cubes (the centre if none)
};

/// Distance field, mesh, centroid and bounds of `grid` (the velocity is left empty). The field
/// is signedDistanceFieldInBand(grid, band, threads): exact inside the body and up to `band` (m)
/// outside it, `band` beyond; +infinity (the default) gives the whole field.
UserFrame describeUser(const VoxelGrid& grid, double band = std::numeric_limits<double>::infinity(),
                       int threads = 1);

/// The ids a user animator draws once.
struct UserIds {
  std::uint64_t object = 0, mesh = 0, sdf = 0, velocity = 0;
};

/// Adds the frame's mesh, distance field and (when present) velocity field as dynamic resources,
/// then the user's object chunk: with `add` every parameter (orientation identity, the resource
/// ids), else an update of position and bounds.
void writeUser(msg::MessageBuilder& builder, const UserIds& ids, const UserFrame& frame, bool add);

}  // namespace vrflow::camera
