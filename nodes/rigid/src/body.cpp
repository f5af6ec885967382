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

Mat3 rotationMatrix(const Quat& q) {
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  return {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
          2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
          2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
}

Mat3 rotateTensor(const Mat3& r, const Mat3& m) {
  Mat3 rm{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) rm[i * 3 + j] += r[i * 3 + k] * m[k * 3 + j];
  Mat3 out{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) out[i * 3 + j] += rm[i * 3 + k] * r[j * 3 + k];
  return out;
}

Mat3 inverse(const Mat3& m) {
  const double c00 = m[4] * m[8] - m[5] * m[7];
  const double c01 = m[5] * m[6] - m[3] * m[8];
  const double c02 = m[3] * m[7] - m[4] * m[6];
  const double det = m[0] * c00 + m[1] * c01 + m[2] * c02;
  if (!(std::abs(det) > 0) || !std::isfinite(det)) return Mat3{};
  const double s = 1.0 / det;
  return {c00 * s, (m[2] * m[7] - m[1] * m[8]) * s, (m[1] * m[5] - m[2] * m[4]) * s,
          c01 * s, (m[0] * m[8] - m[2] * m[6]) * s, (m[2] * m[3] - m[0] * m[5]) * s,
          c02 * s, (m[1] * m[6] - m[0] * m[7]) * s, (m[0] * m[4] - m[1] * m[3]) * s};
}

Mat3 worldInverseInertia(const Body& body) {
  if (body.kinematic) return Mat3{};
  return rotateTensor(rotationMatrix(body.orientation), inverse(body.inertia));
}

Vec3 angularMomentum(const Body& body) {
  const Mat3 iw = rotateTensor(rotationMatrix(body.orientation), body.inertia);
  return mul(iw, body.angularVelocity);
}

double kineticEnergy(const Body& body) {
  if (body.kinematic) return 0.0;
  const Mat3 iw = rotateTensor(rotationMatrix(body.orientation), body.inertia);
  return 0.5 * body.mass * dot(body.linearVelocity, body.linearVelocity) +
         0.5 * dot(body.angularVelocity, mul(iw, body.angularVelocity));
}

}  // namespace vrflow::rigid
