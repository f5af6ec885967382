#pragma once
// The captured user as the interactors see it: a kinematic solid of infinite mass given by its
// signed distance field (metres, negative inside) and the velocity field of its surface, both
// sampled at the cell centres of one regular grid (the wire's ScalarField and VectorField
// layout, docs/message-layout.md). Sampling is trilinear; beyond the grid the distance grows with
// the distance to the grid's box and the velocity is zero. Needs no OpenCV: the rigid,
// mass-spring and fluid packages link it (vrflow::camera_user).

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "vrflow/message/values.hpp"

namespace vrflow::camera {

/// One user: where it is and the fields that describe its surface.
struct UserSurface {
  std::uint64_t id = 0;
  msg::Vec3 position{};  ///< centroid of the voxel model (m)
  msg::Aabb bounds;      ///< world box of the occupied voxels (m)
  std::array<std::uint32_t, 3> dims{};
  msg::Vec3 origin{};           ///< world position of cell (0, 0, 0)'s centre
  double spacing = 0;           ///< between cell centres (m)
  std::vector<float> sdf;       ///< one per cell, x fastest; empty until it arrived
  std::vector<float> velocity;  ///< three per cell; empty when the user sends none

  /// True once a distance field of the stated size is held.
  bool ready() const;
  /// Signed distance (m) at world point p, negative inside.
  double distance(const msg::Vec3& p) const;
  /// Unit outward normal at p (the distance field's gradient, central differences of the
  /// trilinear field half a cell apart); zero where the gradient vanishes.
  msg::Vec3 normal(const msg::Vec3& p) const;
  /// Velocity (m/s) of the user's surface near p; zero beyond the grid or without a field.
  msg::Vec3 velocityAt(const msg::Vec3& p) const;
};

/// The unit gradient at p of a distance function (central differences h apart on each axis);
/// zero where it vanishes. UserSurface::normal is this over its own field; a reader blending two
/// frames' fields uses it over the blend.
template <class Distance>
msg::Vec3 unitGradient(const Distance& distance, const msg::Vec3& p, double h) {
  msg::Vec3 g{};
  double norm = 0;
  for (int a = 0; a < 3; ++a) {
    msg::Vec3 lo = p, hi = p;
    lo[a] -= h;
    hi[a] += h;
    g[a] = (distance(hi) - distance(lo)) / (2 * h);
    norm += g[a] * g[a];
  }
  norm = std::sqrt(norm);
  if (!(norm > 1e-6)) return {};
  for (double& x : g) x /= norm;
  return g;
}

}  // namespace vrflow::camera
