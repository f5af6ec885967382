#pragma once

#include <array>

// ParamKind names its enumerators after these types; declaring it first keeps GCC's -Wshadow
// quiet whatever order a file includes the two headers in.
#include "vrflow/message/object_type.hpp"

// Plain value types carried by object parameters and events. Doubles, one world frame.

namespace vrflow::msg {

/// A 3-vector (x, y, z).
using Vec3 = std::array<double, 3>;
/// A unit quaternion stored (x, y, z, w), the order of Eigen's coeffs() and Bullet.
using Quat = std::array<double, 4>;
/// A 3x3 matrix, row-major.
using Mat3 = std::array<double, 9>;

/// An axis-aligned bounding box.
struct Aabb {
  Vec3 min{};
  Vec3 max{};
  bool operator==(const Aabb&) const = default;
};

/// A force and torque applied to one object at a world point for `duration` seconds.
struct ForceEvent {
  Vec3 force{};
  Vec3 torque{};
  Vec3 point{};
  double duration = 0.0;
  bool operator==(const ForceEvent&) const = default;
};

}  // namespace vrflow::msg
