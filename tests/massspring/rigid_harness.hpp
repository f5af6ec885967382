#pragma once

// A rigid body integrated in the test from the ForceEvents that rigidContacts returns (what the
// rigid animator does in a network), for the contact tests.

#include <algorithm>
#include <cmath>

#include "vrflow/massspring/contact.hpp"
#include "vrflow/massspring/net.hpp"

namespace vrflow::massspring {

using msg::Vec3;

// A free rigid body integrated with semi-implicit Euler from ForceEvents (force at its centre of
// mass plus torque) and gravity; orientation from the angular velocity (first order, normalised).
struct Box {
  RigidBody body;
  Vec3 halfExtents{};
  msg::Mat3 inertia{};
};

inline Box makeBox(const Vec3& half, double mass, const Vec3& position) {
  Box box;
  box.halfExtents = half;
  box.body.shape = msg::Shape::box(half);
  box.body.mass = mass;
  box.body.position = position;
  box.inertia = msg::massProperties(box.body.shape, mass).inertia;
  return box;
}

inline void integrate(Box& box, const msg::ForceEvent* event, const Vec3& g, double dt) {
  auto& b = box.body;
  Vec3 torque{};
  for (int k = 0; k < 3; ++k) {
    const double f = (event ? event->force[k] : 0.0) + b.mass * g[k];
    b.linearVelocity[k] += dt * f / b.mass;
    b.position[k] += dt * b.linearVelocity[k];
    torque[k] = event ? event->torque[k] : 0.0;
  }
  // World torque to body frame, divide by the (diagonal) body inertia, back to world.
  const Vec3 local = msg::rotateInverse(b.orientation, torque);
  const Vec3 alpha = msg::rotate(
      b.orientation,
      {local[0] / box.inertia[0], local[1] / box.inertia[4], local[2] / box.inertia[8]});
  for (int k = 0; k < 3; ++k) b.angularVelocity[k] += dt * alpha[k];
  const auto& w = b.angularVelocity;
  auto& q = b.orientation;
  const msg::Quat dq{0.5 * dt * (w[0] * q[3] + w[1] * q[2] - w[2] * q[1]),
                     0.5 * dt * (w[1] * q[3] + w[2] * q[0] - w[0] * q[2]),
                     0.5 * dt * (w[2] * q[3] + w[0] * q[1] - w[1] * q[0]),
                     0.5 * dt * (-w[0] * q[0] - w[1] * q[1] - w[2] * q[2])};
  double norm = 0;
  for (int k = 0; k < 4; ++k) {
    q[k] += dq[k];
    norm += q[k] * q[k];
  }
  for (auto& c : q) c /= std::sqrt(norm);
}

inline double lowestCorner(const Box& box) {
  double lowest = 1e300;
  for (int c = 0; c < 8; ++c) {
    const Vec3 local{(c & 1 ? 1 : -1) * box.halfExtents[0], (c & 2 ? 1 : -1) * box.halfExtents[1],
                     (c & 4 ? 1 : -1) * box.halfExtents[2]};
    lowest = std::min(lowest, box.body.position[1] + msg::rotate(box.body.orientation, local)[1]);
  }
  return lowest;
}

// The height of the net's surface under (x, z): the triangle whose x-z projection holds it,
// interpolated (nan outside the net).
inline double surfaceHeight(const Net& net, double x, double z) {
  for (std::size_t t = 0; t + 2 < net.surface.size(); t += 3) {
    const auto a = net.position(net.surface[t]), b = net.position(net.surface[t + 1]),
               c = net.position(net.surface[t + 2]);
    const double det = (b[0] - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (b[2] - a[2]);
    if (std::abs(det) < 1e-15) continue;
    const double u = ((x - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (z - a[2])) / det;
    const double v = ((b[0] - a[0]) * (z - a[2]) - (x - a[0]) * (b[2] - a[2])) / det;
    if (u < -1e-12 || v < -1e-12 || u + v > 1 + 1e-12) continue;
    return a[1] + u * (b[1] - a[1]) + v * (c[1] - a[1]);
  }
  return std::nan("");
}

}  // namespace vrflow::massspring
