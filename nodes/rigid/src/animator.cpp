#include "vrflow/rigid/animator.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace vrflow::rigid {
namespace {

Quat normalized(const Quat& q) {
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(n > 0)) return {0, 0, 0, 1};
  return {q[0] / n, q[1] / n, q[2] / n, q[3] / n};
}

// q' = q + dt/2 [w, 0] q, renormalised. The product and the norm are written out in the order
// the examples' digests were recorded with (Eigen's 4-wide products and norms sum differently).
Quat integrate(const Quat& q, const Eigen::Vector3d& w, double dt) {
  const double h = 0.5 * dt;
  const Quat dq{w[0] * q[3] + w[1] * q[2] - w[2] * q[1], w[1] * q[3] + w[2] * q[0] - w[0] * q[2],
                w[2] * q[3] + w[0] * q[1] - w[1] * q[0], -w[0] * q[0] - w[1] * q[1] - w[2] * q[2]};
  return normalized({q[0] + h * dq[0], q[1] + h * dq[1], q[2] + h * dq[2], q[3] + h * dq[3]});
}

/// The body's rotation as a row-major matrix.
RowMatrix3d rotationOf(const Body& body) {
  return asEigen(body.orientation).toRotationMatrix();
}

}  // namespace

Status RigidAnimatorState::addBody(Body body) {
  if (index_.contains(body.id))
    return makeError("rigid body " + std::to_string(body.id) + " exists already");
  if (!body.kinematic && !(body.mass > 0 && std::isfinite(body.mass)))
    return makeError("rigid body " + std::to_string(body.id) +
                     ": mass must be positive and finite");
  if (body.kinematic) body.mass = kInfiniteMass;
  body.orientation = normalized(body.orientation);
  const auto at = std::lower_bound(bodies_.begin(), bodies_.end(), body.id,
                                   [](const Body& b, std::uint64_t id) { return b.id < id; });
  const auto offset = at - bodies_.begin();
  const bool last = at == bodies_.end();
  const std::uint64_t id = body.id;
  bodies_.insert(at, std::move(body));
  impulses_.insert(impulses_.begin() + offset, Accumulator{});
  stepForces_.insert(stepForces_.begin() + offset, Accumulator{});
  rest_.insert(rest_.begin() + offset, Rest{});
  if (last) {
    index_[id] = bodies_.size() - 1;  // ids in increasing order: no reindexing
  } else {
    reindex();
  }
  return {};
}

Status RigidAnimatorState::removeBody(std::uint64_t id) {
  const auto it = index_.find(id);
  if (it == index_.end()) return makeError("no rigid body " + std::to_string(id));
  const auto offset = static_cast<std::ptrdiff_t>(it->second);
  bodies_.erase(bodies_.begin() + offset);
  impulses_.erase(impulses_.begin() + offset);
  stepForces_.erase(stepForces_.begin() + offset);
  rest_.erase(rest_.begin() + offset);
  reindex();
  return {};
}

void RigidAnimatorState::reindex() {
  index_.clear();
  for (std::size_t i = 0; i < bodies_.size(); ++i) index_[bodies_[i].id] = i;
}

bool RigidAnimatorState::asleep(std::uint64_t id) const {
  const auto it = index_.find(id);
  return it != index_.end() && rest_[it->second].asleep;
}

const Body* RigidAnimatorState::find(std::uint64_t id) const {
  const auto it = index_.find(id);
  return it == index_.end() ? nullptr : &bodies_[it->second];
}

Body* RigidAnimatorState::find(std::uint64_t id) {
  const auto it = index_.find(id);
  return it == index_.end() ? nullptr : &bodies_[it->second];
}

bool RigidAnimatorState::applyForce(std::uint64_t id, const msg::ForceEvent& event) {
  const auto it = index_.find(id);
  if (it == index_.end()) return false;
  const Body& body = bodies_[it->second];
  if (body.kinematic) return true;
  // duration <= 0 means "over the step": kept as a force and scaled by dt in step().
  Accumulator& acc = impulses_[it->second];
  const double duration = event.duration > 0 ? event.duration : -1.0;
  const Eigen::Vector3d arm = asEigen(event.point) - asEigen(body.position);
  const Eigen::Vector3d torque = asEigen(event.torque) + arm.cross(asEigen(event.force));
  if (duration > 0) {
    asEigen(acc.linear) += asEigen(event.force) * duration;
    asEigen(acc.angular) += torque * duration;
  } else {
    asEigen(stepForces_[it->second].linear) += asEigen(event.force);
    asEigen(stepForces_[it->second].angular) += torque;
  }
  return true;
}

std::vector<Change> RigidAnimatorState::step(double dt) {
  std::vector<Change> changes;
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    Body& b = bodies_[i];
    Change change{b.id, false, false};
    if (b.kinematic) {
      if (!asEigen(b.linearVelocity).isZero(0.0)) {
        asEigen(b.position) += asEigen(b.linearVelocity) * dt;
        change.pose = true;
      }
      if (!asEigen(b.angularVelocity).isZero(0.0)) {
        b.orientation = integrate(b.orientation, asEigen(b.angularVelocity), dt);
        change.pose = true;
      }
    } else {
      const Eigen::Vector3d linear =
          asEigen(impulses_[i].linear) + asEigen(stepForces_[i].linear) * dt;
      const Eigen::Vector3d angular =
          asEigen(impulses_[i].angular) + asEigen(stepForces_[i].angular) * dt;
      Rest& rest = rest_[i];
      if (rest.asleep) {
        // A sleeping body stays put while the impulses it receives nearly cancel (its weight
        // and its support); a blow or a lost support wakes it.
        const Eigen::Vector3d dv = linear * (1.0 / b.mass);
        const Eigen::Vector3d dw =
            rotateTensor(rotationOf(b), inverse(asEigen(b.inertia))) * angular;
        if (dv.norm() < sleep_.wakeLinear && dw.norm() < sleep_.wakeAngular) {
          impulses_[i] = Accumulator{};
          stepForces_[i] = Accumulator{};
          continue;
        }
        rest = Rest{};
      }
      const Vec3 v0 = b.linearVelocity, w0 = b.angularVelocity;
      const Quat q0 = b.orientation;
      const Vec3 p0 = b.position;
      asEigen(b.linearVelocity) += linear * (1.0 / b.mass);
      asEigen(b.position) += asEigen(b.linearVelocity) * dt;
      if (!asEigen(b.angularVelocity).isZero(0.0) || !angular.isZero(0.0)) {
        const RowMatrix3d inertiaInverse = inverse(asEigen(b.inertia));
        // Angular momentum in the world frame with the current orientation, plus the impulse.
        const Eigen::Vector3d momentum =
            rotateTensor(rotationOf(b), asEigen(b.inertia)) * asEigen(b.angularVelocity) + angular;
        const Eigen::Vector3d w = rotateTensor(rotationOf(b), inertiaInverse) * momentum;
        b.orientation = integrate(b.orientation, w, dt);
        asEigen(b.angularVelocity) = rotateTensor(rotationOf(b), inertiaInverse) * momentum;
      }
      if (sleep_.enabled) {
        const bool slow = asEigen(b.linearVelocity).norm() < sleep_.linear &&
                          asEigen(b.angularVelocity).norm() < sleep_.angular;
        rest.still = slow ? rest.still + dt : 0.0;
        if (slow && rest.still >= sleep_.time) {
          rest.asleep = true;
          b.linearVelocity = {0, 0, 0};
          b.angularVelocity = {0, 0, 0};
        }
      }
      change.pose = b.position != p0 || b.orientation != q0;
      change.velocity = b.linearVelocity != v0 || b.angularVelocity != w0;
    }
    impulses_[i] = Accumulator{};
    stepForces_[i] = Accumulator{};
    if (change.pose || change.velocity) changes.push_back(change);
  }
  time_ += dt;
  return changes;
}

}  // namespace vrflow::rigid
