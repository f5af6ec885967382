#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "vrflow/message/values.hpp"

// Eigen views of the wire's plain value types (values.hpp), so that the packages do their
// geometry with Eigen while the message layout keeps plain arrays of doubles.
//
// Quaternions: the wire stores (x, y, z, w), which is Eigen::Quaterniond's storage order
// (coeffs() is x, y, z, w), so asEigen(q) maps the wire's four doubles as they are. Eigen's
// constructor takes w first: Eigen::Quaterniond(w, x, y, z). Write a wire quaternion with toQuat().
// Matrices: the wire's Mat3 is row-major, asEigen maps it as a RowMatrix3d.
// Header-only; include it only from targets that link Eigen3::Eigen (the node packages do);
// vrflow::message itself uses Eigen privately, so its users do not see Eigen.

namespace vrflow::msg {

/// A row-major 3x3 matrix, the layout of Mat3.
using RowMatrix3d = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

/// The wire vector as an Eigen vector (no copy).
inline Eigen::Map<Eigen::Vector3d> asEigen(Vec3& v) {
  return Eigen::Map<Eigen::Vector3d>(v.data());
}
/// The wire vector as a read-only Eigen vector (no copy).
inline Eigen::Map<const Eigen::Vector3d> asEigen(const Vec3& v) {
  return Eigen::Map<const Eigen::Vector3d>(v.data());
}
/// The wire quaternion (x, y, z, w) as an Eigen quaternion (no copy).
inline Eigen::Map<Eigen::Quaterniond> asEigen(Quat& q) {
  return Eigen::Map<Eigen::Quaterniond>(q.data());
}
/// The wire quaternion (x, y, z, w) as a read-only Eigen quaternion (no copy).
inline Eigen::Map<const Eigen::Quaterniond> asEigen(const Quat& q) {
  return Eigen::Map<const Eigen::Quaterniond>(q.data());
}
/// The wire's row-major matrix as an Eigen matrix (no copy).
inline Eigen::Map<RowMatrix3d> asEigen(Mat3& m) {
  return Eigen::Map<RowMatrix3d>(m.data());
}
/// The wire's row-major matrix as a read-only Eigen matrix (no copy).
inline Eigen::Map<const RowMatrix3d> asEigen(const Mat3& m) {
  return Eigen::Map<const RowMatrix3d>(m.data());
}
/// Three consecutive doubles of a flat array (a net's positions, a shape's vertices) as a vector.
inline Eigen::Map<const Eigen::Vector3d> asVector3(const double* xyz) {
  return Eigen::Map<const Eigen::Vector3d>(xyz);
}
/// Three consecutive doubles of a flat array as a writable vector.
inline Eigen::Map<Eigen::Vector3d> asVector3(double* xyz) {
  return Eigen::Map<Eigen::Vector3d>(xyz);
}

/// An Eigen 3-vector expression evaluated into a wire vector.
template <typename Derived>
Vec3 toVec3(const Eigen::MatrixBase<Derived>& v) {
  const Eigen::Vector3d e = v;
  return {e[0], e[1], e[2]};
}
/// An Eigen quaternion as a wire quaternion (x, y, z, w).
template <typename Derived>
Quat toQuat(const Eigen::QuaternionBase<Derived>& q) {
  return {q.x(), q.y(), q.z(), q.w()};
}
/// An Eigen 3x3 matrix expression evaluated into a wire (row-major) matrix.
template <typename Derived>
Mat3 toMat3(const Eigen::MatrixBase<Derived>& m) {
  Mat3 out;
  asEigen(out) = m;
  return out;
}
/// The wire box as an Eigen box.
inline Eigen::AlignedBox3d toEigen(const Aabb& box) {
  return Eigen::AlignedBox3d(asEigen(box.min), asEigen(box.max));
}

}  // namespace vrflow::msg
