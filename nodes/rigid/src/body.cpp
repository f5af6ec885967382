#include "vrflow/rigid/body.hpp"

#include <cmath>

namespace vrflow::rigid {

Body makeBody(std::uint64_t id, const msg::Shape& shape, double mass, const Vec3& position,
              const Quat& orientation) {
  Body body;
  body.id = id;
  body.shape = shape;
  body.mass = mass;
  body.inertia = msg::massProperties(shape, mass).inertia;
  body.position = position;
  body.orientation = orientation;
  return body;
}

Body makeKinematic(std::uint64_t id, const msg::Shape& shape, const Vec3& position,
                   const Quat& orientation) {
  Body body;
  body.id = id;
  body.shape = shape;
  body.mass = kInfiniteMass;
  body.inertia = {kInfiniteMass, 0, 0, 0, kInfiniteMass, 0, 0, 0, kInfiniteMass};
  body.position = position;
  body.orientation = orientation;
  body.kinematic = true;
  return body;
}

RowMatrix3d rotateTensor(const RowMatrix3d& r, const RowMatrix3d& m) {
  // A column-major right factor makes Eigen's lazy product sum each entry over k = 0, 1, 2 in
  // order, as the plain triple loop did (the bits of the examples' digests depend on it).
  const RowMatrix3d rm = r * Eigen::Matrix3d(m);
  return rm * r.transpose();
}

RowMatrix3d inverse(const RowMatrix3d& m) {
  // The adjugate's columns are cross products of the rows; det by the first row.
  const Eigen::Vector3d c0 = m.row(1).cross(m.row(2));
  const double det = m.row(0).dot(c0);
  if (!(std::abs(det) > 0) || !std::isfinite(det)) return RowMatrix3d::Zero();
  const double s = 1.0 / det;
  RowMatrix3d out;
  out.col(0) = c0 * s;
  out.col(1) = m.row(2).cross(m.row(0)).transpose() * s;
  out.col(2) = m.row(0).cross(m.row(1)).transpose() * s;
  return out;
}

namespace {
/// The body's rotation as a row-major matrix (Eigen's toRotationMatrix of the wire quaternion).
RowMatrix3d rotationOf(const Body& body) {
  return asEigen(body.orientation).toRotationMatrix();
}
}  // namespace

RowMatrix3d worldInverseInertia(const Body& body) {
  if (body.kinematic) return RowMatrix3d::Zero();
  return rotateTensor(rotationOf(body), inverse(asEigen(body.inertia)));
}

Eigen::Vector3d angularMomentum(const Body& body) {
  return rotateTensor(rotationOf(body), asEigen(body.inertia)) * asEigen(body.angularVelocity);
}

double kineticEnergy(const Body& body) {
  if (body.kinematic) return 0.0;
  const RowMatrix3d iw = rotateTensor(rotationOf(body), asEigen(body.inertia));
  const Eigen::Vector3d v = asEigen(body.linearVelocity), w = asEigen(body.angularVelocity);
  return 0.5 * body.mass * v.dot(v) + 0.5 * w.dot(iw * w);
}

}  // namespace vrflow::rigid
