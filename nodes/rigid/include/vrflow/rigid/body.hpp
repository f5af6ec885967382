#pragma once

#include <cstdint>
#include <limits>

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

  double inverseMass() const { return kinematic ? 0.0 : 1.0 / mass; }
};

/// A dynamic body of the given shape and mass (inertia from the shape, uniform density).
Body makeBody(std::uint64_t id, const msg::Shape& shape, double mass, const Vec3& position,
              const Quat& orientation = {0, 0, 0, 1});
/// A kinematic (infinite-mass) body.
Body makeKinematic(std::uint64_t id, const msg::Shape& shape, const Vec3& position,
                   const Quat& orientation = {0, 0, 0, 1});

inline constexpr double kInfiniteMass = std::numeric_limits<double>::infinity();

// Small vector helpers shared by the solvers.
inline Vec3 add(const Vec3& a, const Vec3& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
inline Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline Vec3 scale(const Vec3& a, double s) {
  return {a[0] * s, a[1] * s, a[2] * s};
}
inline double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline Vec3 mul(const Mat3& m, const Vec3& v) {
  return {m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
          m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
}
/// Rotation matrix (row-major) of a unit quaternion (x, y, z, w).
Mat3 rotationMatrix(const Quat& q);
/// R M R^T.
Mat3 rotateTensor(const Mat3& r, const Mat3& m);
/// Inverse of a symmetric positive definite 3x3 matrix (zero matrix if singular).
Mat3 inverse(const Mat3& m);
/// The inverse inertia in the world frame, R I_b^-1 R^T (zero for a kinematic body).
Mat3 worldInverseInertia(const Body& body);
/// Kinetic energy and momenta (for tests and diagnostics).
Vec3 angularMomentum(const Body& body);
double kineticEnergy(const Body& body);

}  // namespace vrflow::rigid
