#include "vrflow/massspring/user_collider.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

namespace vrflow::massspring {
namespace {

using Eigen::Vector3d;

Vector3d asEigen(const msg::Vec3& v) {
  return {v[0], v[1], v[2]};
}
msg::Vec3 asVec3(const Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}
Vector3d nodeOf(std::span<const double> values, std::size_t i) {
  return {values[3 * i], values[3 * i + 1], values[3 * i + 2]};
}

/// A user's field over the sub-steps: its last frame blended in from the frame before by
/// `alpha` (0: the frame before, 1: the last frame), so the surface sweeps over the outer step
/// instead of jumping at its start. Without a frame before, the last frame.
class Field {
 public:
  Field(const camera::UserSurface& now, const camera::UserSurface* before, double alpha)
      : now_(now),
        before_(before && before->ready() && alpha < 1 ? before : nullptr),
        alpha_(alpha),
        spacing(now.spacing),
        bounds(now.bounds) {
    if (!before_) return;
    for (int k = 0; k < 3; ++k) {
      bounds.min[k] = std::min(bounds.min[k], before_->bounds.min[k]);
      bounds.max[k] = std::max(bounds.max[k], before_->bounds.max[k]);
    }
  }
  double distance(const msg::Vec3& p) const {
    const double d = now_.distance(p);
    return before_ ? alpha_ * d + (1 - alpha_) * before_->distance(p) : d;
  }
  /// The blended field's unit gradient (central differences half a cell apart, as
  /// UserSurface::normal); zero where it vanishes.
  msg::Vec3 normal(const msg::Vec3& p) const {
    if (!before_) return now_.normal(p);
    return camera::unitGradient([this](const msg::Vec3& q) { return distance(q); }, p,
                                0.5 * spacing);
  }
  msg::Vec3 velocityAt(const msg::Vec3& p) const { return now_.velocityAt(p); }

 private:
  const camera::UserSurface& now_;
  const camera::UserSurface* before_;
  double alpha_;

 public:
  const double spacing;  ///< the last frame's cell spacing (m)
  msg::Aabb bounds;      ///< both frames' boxes
};

/// Whether the box of the path a -> b meets `box` grown by `margin`.
bool pathNearBox(const Vector3d& a, const Vector3d& b, const msg::Aabb& box, double margin) {
  for (int k = 0; k < 3; ++k) {
    if (std::max(a[k], b[k]) < box.min[k] - margin || std::min(a[k], b[k]) > box.max[k] + margin)
      return false;
  }
  return true;
}

/// Moves x out of the user to `thickness` from its surface along the field's gradient; where
/// the gradient points away from `side` (the side the node came from: past the middle of a thin
/// part) or vanishes, along `side`, by at least a cell, until it agrees again. Returns the outward
/// normal where x ends (zero when neither the gradient nor a side says where out is).
Vector3d pushOut(const Field& user, Vector3d& x, const Vector3d& side, double thickness) {
  constexpr int kRounds = 32;
  const double tolerance = 1e-4 * thickness;
  Vector3d n = Vector3d::Zero();
  for (int round = 0; round < kRounds; ++round) {
    const double d = user.distance(asVec3(x));
    n = asEigen(user.normal(asVec3(x)));
    const bool wrongSide = !side.isZero(0.0) && (n.isZero(0.0) || n.dot(side) < 0);
    if (d >= thickness - tolerance) return wrongSide ? side : n;
    if (wrongSide) {
      x += std::max(thickness - d, user.spacing) * side;
    } else if (n.isZero(0.0)) {
      return n;
    } else {
      x += (thickness - d) * n;
    }
  }
  return n;
}

/// The first point of the path a -> b (a outside) closer than `thickness` to the user, found by
/// samples `step` apart and then bisection to the last point outside; false when none is.
bool firstEntry(const Field& user, const Vector3d& a, const Vector3d& b, double thickness,
                double step, Vector3d& entry) {
  const double length = (b - a).norm();
  if (!(length > 0)) return false;
  const int samples = static_cast<int>(std::min(1000.0, std::ceil(length / step)));
  double outside = 0;
  for (int k = 1; k <= samples; ++k) {
    const double t = static_cast<double>(k) / samples;
    if (user.distance(asVec3(a + t * (b - a))) >= thickness) {
      outside = t;
      continue;
    }
    double inside = t;
    for (int round = 0; round < 20; ++round) {
      const double mid = 0.5 * (outside + inside);
      if (user.distance(asVec3(a + mid * (b - a))) >= thickness)
        outside = mid;
      else
        inside = mid;
    }
    entry = a + outside * (b - a);
    return true;
  }
  return false;
}

}  // namespace

Status validateUserColliderParams(const UserColliderParams& p) {
  if (!(p.thickness > 0) || !std::isfinite(p.thickness))
    return makeError("mass-spring user collider: thickness must be finite and > 0");
  if (!(p.friction >= 0) || !std::isfinite(p.friction))
    return makeError("mass-spring user collider: friction must be finite and >= 0");
  return {};
}

namespace {

/// Where a point of the net that moved from `from` to `x` over the sub-step must be: nullopt
/// when it stays clear of the user (`side` then takes the outward normal there, when known);
/// else the point out of the user and the outward normal there (`side` updated to it).
struct Resolved {
  Vector3d point;
  Vector3d normal;
};
std::optional<Resolved> resolve(const Field& user, const Vector3d& from, const Vector3d& x,
                                bool withPath, Vector3d& side, double thickness, double step) {
  if (side.isZero(0.0) && withPath && user.distance(asVec3(from)) >= thickness)
    side = asEigen(user.normal(asVec3(from)));
  Vector3d target = x;
  if (user.distance(asVec3(x)) >= thickness) {
    // Outside at the end of the sub-step: in contact only if its path crossed the user.
    Vector3d entry;
    if (!withPath || user.distance(asVec3(from)) < thickness ||
        !firstEntry(user, from, x, thickness, step, entry)) {
      const Vector3d outward = asEigen(user.normal(asVec3(x)));
      if (!outward.isZero(0.0)) side = outward;
      return std::nullopt;
    }
    target = entry;
  }
  const Vector3d n = pushOut(user, target, side, thickness);
  if (n.isZero(0.0)) return std::nullopt;
  side = n;
  return Resolved{target, n};
}

/// The velocity change that makes a point moving at `v` inelastic against the user's surface
/// (moving at `surface`, outward normal n), with Coulomb friction on its tangential part.
Vector3d responseTo(const Vector3d& v, const Vector3d& surface, const Vector3d& n,
                    double friction) {
  Vector3d relative = v - surface;
  const double normalSpeed = relative.dot(n);
  if (normalSpeed >= 0) return Vector3d::Zero();
  const Vector3d before = relative;
  relative -= normalSpeed * n;
  const double slide = relative.norm();
  const double stop = friction * -normalSpeed;
  if (slide > 0) relative *= slide > stop ? 1.0 - stop / slide : 0.0;
  return relative - before;
}

/// The points of the surface tested besides the nodes: each triangle's centroid and its edges'
/// middles, as barycentric weights (a hand narrower than the net's spacing passes between nodes).
constexpr std::array<std::array<double, 3>, 4> kSurfacePoints{
    {{1.0 / 3, 1.0 / 3, 1.0 / 3}, {0.5, 0.5, 0.0}, {0.0, 0.5, 0.5}, {0.5, 0.0, 0.5}}};

}  // namespace

std::size_t collideWithUsers(Net& net, std::span<const double> before,
                             const UserColliders& colliders, double blend) {
  const double thickness = colliders.params.thickness;
  const double friction = colliders.params.friction;
  const bool withPath = before.size() == net.positions.size();
  std::size_t projected = 0;
  for (const auto& [userId, surface] : colliders.users) {
    if (!surface || !surface->ready()) continue;
    const auto previous = colliders.previous.find(userId);
    const Field field(*surface, previous == colliders.previous.end() ? nullptr : previous->second,
                      blend);
    const Field* user = &field;
    std::vector<msg::Vec3> scratch;
    std::vector<msg::Vec3>* sides = &scratch;
    if (colliders.memory) sides = &colliders.memory->sides[userId];
    if (sides->size() != net.nodeCount()) sides->assign(net.nodeCount(), msg::Vec3{});
    // Points within a voxel of the user's box are watched, so that a node its next frame
    // swallows has its side remembered; the path test reaches as far as the point moved.
    const double watch = thickness + user->spacing;
    const double step = std::max(0.5 * thickness, 0.25 * user->spacing);
    // The nodes: each goes out of the user on its own.
    for (std::size_t i = 0; i < net.nodeCount(); ++i) {
      if (net.pinned[i]) continue;
      const Vector3d x = nodeOf(net.positions, i);
      const Vector3d from = withPath ? nodeOf(before, i) : x;
      if (!pathNearBox(from, x, user->bounds, watch)) continue;
      Vector3d side = asEigen((*sides)[i]);
      const auto hit = resolve(*user, from, x, withPath, side, thickness, step);
      (*sides)[i] = asVec3(side);
      if (!hit) continue;
      ++projected;
      const Vector3d v = nodeOf(net.velocities, i);
      const Vector3d dv =
          responseTo(v, asEigen(user->velocityAt(asVec3(hit->point))), hit->normal, friction);
      for (int k = 0; k < 3; ++k) {
        net.positions[3 * i + k] = hit->point[k];
        net.velocities[3 * i + k] = v[k] + dv[k];
      }
    }
    // The surface between the nodes: a point inside the user moves its triangle's nodes by
    // their weights (inverse-mass weighted, the least change that moves the point out), and its
    // velocity change is shared the same way.
    for (std::size_t t = 0; t + 2 < net.surface.size(); t += 3) {
      const std::array<std::uint32_t, 3> nodes{net.surface[t], net.surface[t + 1],
                                               net.surface[t + 2]};
      std::array<double, 3> inverseMass{};
      for (int c = 0; c < 3; ++c)
        inverseMass[c] = net.pinned[nodes[c]] ? 0.0 : 1.0 / net.masses[nodes[c]];
      if (inverseMass[0] + inverseMass[1] + inverseMass[2] == 0) continue;
      for (const auto& w : kSurfacePoints) {
        Vector3d x = Vector3d::Zero(), from = Vector3d::Zero(), v = Vector3d::Zero(),
                 side = Vector3d::Zero();
        for (int c = 0; c < 3; ++c) {
          x += w[c] * nodeOf(net.positions, nodes[c]);
          from += w[c] * (withPath ? nodeOf(before, nodes[c]) : nodeOf(net.positions, nodes[c]));
          v += w[c] * nodeOf(net.velocities, nodes[c]);
          side += w[c] * asEigen((*sides)[nodes[c]]);
        }
        if (!pathNearBox(from, x, user->bounds, watch)) continue;
        if (side.norm() > 1e-6)
          side.normalize();
        else
          side.setZero();
        const auto hit = resolve(*user, from, x, withPath, side, thickness, step);
        if (!hit) continue;
        ++projected;
        double weight = 0;
        for (int c = 0; c < 3; ++c) weight += w[c] * w[c] * inverseMass[c];
        const Vector3d dx = (hit->point - x) / weight;
        const Vector3d dv =
            responseTo(v, asEigen(user->velocityAt(asVec3(hit->point))), hit->normal, friction) /
            weight;
        for (int c = 0; c < 3; ++c) {
          const double share = w[c] * inverseMass[c];
          if (share == 0) continue;
          for (int k = 0; k < 3; ++k) {
            net.positions[3 * nodes[c] + k] += share * dx[k];
            net.velocities[3 * nodes[c] + k] += share * dv[k];
          }
        }
      }
    }
  }
  return projected;
}

}  // namespace vrflow::massspring
