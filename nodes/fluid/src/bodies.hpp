#pragma once

#include <vector>

#include "grid.hpp"
#include "vrflow/fluid/solver.hpp"

// Rigid bodies in the grid: checked and prepared once per step, rasterised into cells and faces
// (by the sign of the shape's distance at their centres), their rigid velocity field, and the
// force the projection left on them.

namespace vrflow::fluid::detail {

struct PreparedBody {
  std::uint64_t id = 0;
  std::uint32_t index = 0;
  bool point = false;      ///< a mass-spring node (only validated: node_coupling.hpp)
  bool kinematic = false;  ///< a moving wall for the liquid
  msg::Shape shape;
  msg::Vec3 position{};
  msg::Quat orientation{0, 0, 0, 1};
  msg::Vec3 linearVelocity{};
  msg::Vec3 angularVelocity{};
  double mass = 1.0;
  double density = 1.0;                          ///< mass / volume, used in the projection
  msg::Aabb bounds;                              ///< world bounds
  const camera::UserSurface* surface = nullptr;  ///< a captured user: distance and velocity fields
};

/// `liquidDensity` gives kinematic bodies theirs (kKinematicDensityRatio times it).
Result<PreparedBody> prepareBody(const RigidBody& body, double liquidDensity);
Result<PreparedBody> preparePoint(const PointMass& point);

/// Inline: tested for every particle in a cell some body's bounds reach.
inline bool inBounds(const msg::Aabb& box, const double* x) {
  return x[0] >= box.min[0] && x[0] <= box.max[0] && x[1] >= box.min[1] && x[1] <= box.max[1] &&
         x[2] >= box.min[2] && x[2] <= box.max[2];
}
/// Moves a world point inside the body to `margin` outside its surface.
void pushOut(const PreparedBody& body, double* x, double margin);
/// Velocity of the body's material at world point x.
msg::Vec3 rigidVelocity(const PreparedBody& body, const msg::Vec3& x);
/// Marks cells and faces whose centres lie inside a body with its index (first body wins).
void rasterise(const Grid& grid, const std::vector<PreparedBody>& bodies,
               std::vector<int>& cellBody, std::vector<int>* faceBody);
/// Values bodyForceSums() adds up per body: per axis the summed velocity change, the face count
/// and the torque of the change (3), so that blocks can add theirs before finishBodyForce().
inline constexpr int kBodySums = 15;
/// Adds the momentum change per unit mass (less gravity) of the body's faces in z-planes
/// [k0, k1) of each component (k1 of the w faces is given by `kEnd[2]`) to `sums`.
void bodyForceSums(const Grid& grid, const PreparedBody& body, int bodyIndex,
                   const std::vector<int>* faceBody, const std::vector<double>* uNew,
                   const std::vector<double>* uOld, const msg::Vec3& gravity, double dt, int k0,
                   const int kEnd[3], double* sums);
/// Force and torque from the summed changes: mass times the mean change per axis, over dt.
BodyForce finishBodyForce(const PreparedBody& body, const double* sums, double dt);

}  // namespace vrflow::fluid::detail
