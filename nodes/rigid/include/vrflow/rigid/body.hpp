#pragma once

#include <cstdint>
#include <limits>

#include "vrflow/message/eigen.hpp"
#include "vrflow/message/object_type.hpp"  // before values.hpp, or -Wshadow
#include "vrflow/message/shape.hpp"
#include "vrflow/message/values.hpp"

// A rigid body as the rigid package's solvers see it. Doubles, one world frame, the body frame's
// origin at the centre of mass (the convention of vrflow/message/shape.hpp).

namespace vrflow::rigid {

using msg::Mat3;
using msg::Quat;
using msg::Vec3;

struct Body {
  std::uint64_t id = 0;
  msg::Shape shape;
  /// Mass in kg; +infinity for a kinematic body (also when `kinematic` is set).
  double mass = 1.0;
  /// Inertia tensor about the centre of mass in the body frame (row-major).
  Mat3 inertia{1, 0, 0, 0, 1, 0, 0, 0, 1};
  Vec3 position{};
  Quat orientation{0, 0, 0, 1};
  Vec3 linearVelocity{};
  Vec3 angularVelocity{};
  /// Infinite mass: forces never move it; it moves only with its own (constant) velocities.
  bool kinematic = false;
  /// The surface's material; negative: none of its own (the interactor's `friction` and
  /// `restitution` apply). A pair combines its two bodies' values (combinedFriction,
  /// combinedRestitution in contact_solver.hpp).
  double friction = -1.0;
  double restitution = -1.0;

  double inverseMass() const { return kinematic ? 0.0 : 1.0 / mass; }
};

/// A dynamic body of the given shape and mass (inertia from the shape, uniform density).
Body makeBody(std::uint64_t id, const msg::Shape& shape, double mass, const Vec3& position,
              const Quat& orientation = {0, 0, 0, 1});
/// A kinematic (infinite-mass) body.
Body makeKinematic(std::uint64_t id, const msg::Shape& shape, const Vec3& position,
                   const Quat& orientation = {0, 0, 0, 1});

inline constexpr double kInfiniteMass = std::numeric_limits<double>::infinity();

// Geometry is Eigen's over the Body's wire arrays (vrflow/message/eigen.hpp): asEigen(position)
// is an Eigen::Vector3d, asEigen(orientation) an Eigen::Quaterniond (the wire's x, y, z, w is
// Eigen's storage order), asEigen(inertia) a row-major Eigen 3x3 matrix.
using msg::asEigen;
using msg::RowMatrix3d;

/// R M R^T (the products are written so that they round as the plain loops over k = 0, 1, 2).
RowMatrix3d rotateTensor(const RowMatrix3d& r, const RowMatrix3d& m);
/// Inverse of a symmetric positive definite 3x3 matrix (zero matrix if singular).
RowMatrix3d inverse(const RowMatrix3d& m);
/// The inverse inertia in the world frame, R I_b^-1 R^T (zero for a kinematic body).
RowMatrix3d worldInverseInertia(const Body& body);
/// Kinetic energy and momenta (for tests and diagnostics).
Eigen::Vector3d angularMomentum(const Body& body);
double kineticEnergy(const Body& body);

}  // namespace vrflow::rigid
