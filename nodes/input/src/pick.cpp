// Picking by bounds and the grab's spring-damper.
#include "vrflow/input/pick.hpp"

#include <cmath>
#include <limits>

namespace vrflow::input {

std::optional<PickHit> pick(std::span<const PickTarget> targets, const msg::Vec3& origin,
                            const msg::Vec3& direction) {
  const bool isRay = direction[0] != 0 || direction[1] != 0 || direction[2] != 0;
  std::optional<PickHit> best;
  for (const auto& target : targets) {
    double enter = 0.0, leave = std::numeric_limits<double>::infinity();
    bool missed = false;
    for (int k = 0; k < 3 && !missed; ++k) {
      const double lo = target.bounds.min[k], hi = target.bounds.max[k];
      if (!isRay || direction[k] == 0) {
        missed = origin[k] < lo || origin[k] > hi;
        continue;
      }
      double t0 = (lo - origin[k]) / direction[k], t1 = (hi - origin[k]) / direction[k];
      if (t0 > t1) std::swap(t0, t1);
      enter = std::max(enter, t0);
      leave = std::min(leave, t1);
      missed = enter > leave;
    }
    if (missed || (best && enter >= best->distance)) continue;
    best = PickHit{target.id,
                   enter,
                   {origin[0] + enter * direction[0], origin[1] + enter * direction[1],
                    origin[2] + enter * direction[2]}};
  }
  return best;
}

msg::Vec3 grabForce(const GrabSpring& spring, const msg::Vec3& anchor,
                    const msg::Vec3& anchorVelocity, const msg::Vec3& target) {
  msg::Vec3 force{};
  double length = 0;
  for (int k = 0; k < 3; ++k) {
    force[k] = spring.stiffness * (target[k] - anchor[k]) - spring.damping * anchorVelocity[k];
    length += force[k] * force[k];
  }
  length = std::sqrt(length);
  if (length > spring.maxForce)
    for (auto& f : force) f *= spring.maxForce / length;
  return force;
}

}  // namespace vrflow::input
