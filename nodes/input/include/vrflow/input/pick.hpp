#pragma once

#include <cstdint>
#include <optional>
#include <span>

#include "vrflow/message/values.hpp"

// Picking and grabbing: a ray (or a point) against the objects' bounds, and the spring-damper
// a grab pulls the picked object with.

namespace vrflow::input {

/// An object a pick may hit: its id and its world bounds.
struct PickTarget {
  std::uint64_t id = 0;
  msg::Aabb bounds{};
};

/// The nearest hit: the object, the distance along the ray and the world point.
struct PickHit {
  std::uint64_t id = 0;
  double distance = 0.0;
  msg::Vec3 point{};
};

/// The nearest target whose bounds the ray from `origin` along the unit `direction` enters at
/// or after the origin (slab test); a zero direction picks the first target containing origin.
std::optional<PickHit> pick(std::span<const PickTarget> targets, const msg::Vec3& origin,
                            const msg::Vec3& direction);

/// The grab's spring-damper (defaults as in the grab module's manifest).
struct GrabSpring {
  double stiffness = 200.0;  ///< N/m
  double damping = 10.0;     ///< N s/m, on the anchor's velocity
  double maxForce = 500.0;   ///< N, the force is clamped to this length
};

/// The force on an anchor at `anchor` moving at `anchorVelocity`, pulled towards `target`.
msg::Vec3 grabForce(const GrabSpring& spring, const msg::Vec3& anchor,
                    const msg::Vec3& anchorVelocity, const msg::Vec3& target);

}  // namespace vrflow::input
