#include "vrflow/massspring/contact.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "rigid_solve.hpp"
#include "vrflow/message/eigen.hpp"

namespace vrflow::massspring {
namespace {

using Eigen::Vector3d;
using msg::asEigen;

/// Node i's position and velocity as Eigen vectors (copies of the net's flat arrays).
Vector3d positionOf(const Net& net, std::size_t i) {
  return msg::asVector3(&net.positions[3 * i]);
}
Vector3d velocityOf(const Net& net, std::size_t i) {
  return msg::asVector3(&net.velocities[3 * i]);
}

double invMass(const Net& net, std::size_t i) {
  return net.pinned[i] ? 0.0 : 1.0 / net.masses[i];
}

void addTo(std::vector<double>& forces, std::size_t node, const Vector3d& f) {
  msg::asVector3(&forces[3 * node]) += f;
}

/// The contact force magnitude of the header's formula (0 when not approaching enough).
double contactMagnitude(double distance, double vn, double invMassSum, const ContactParams& p) {
  if (invMassSum <= 0) return 0.0;
  const double target = -vn + p.beta * (p.thickness - distance) / p.dt;
  return std::max(0.0, target / (p.dt * invMassSum));
}

std::vector<double>& forcesOf(ContactForces& out, std::uint64_t id, const Net& net) {
  auto& f = out.nodeForces[id];
  if (f.empty()) f.assign(3 * net.nodeCount(), 0.0);
  return f;
}

bool inBox(const Vector3d& p, const msg::Aabb& box, double margin) {
  const Vector3d grow = Vector3d::Constant(margin);
  return Eigen::AlignedBox3d(asEigen(box.min) - grow, asEigen(box.max) + grow).contains(p);
}

struct PlaneHit {
  bool hit = false;
  double distance = 0;  ///< along normal, negative once crossed
  double gap = 0;       ///< 3-D distance to the closest point (to choose among triangles)
  Vector3d normal = Vector3d::Zero();  ///< unit, pointing to the side the point came from
  TrianglePoint closest;
  int side = 0;  ///< that side along the triangle's own normal (+1 / -1)
};

/// A point x moving at `relative` (point minus surface) against triangle abc. A ball of `radius`
/// around x touches at distance (from its surface) below the thickness; `speculative`: also
/// while it is farther, by no more than it approaches within the step.
PlaneHit pointTriangle(const Vector3d& x, const Vector3d& relative, const Vector3d& a,
                       const Vector3d& b, const Vector3d& c, const ContactParams& p,
                       int knownSide = 0, double radius = 0, bool speculative = false) {
  PlaneHit out;
  Vector3d n = (b - a).cross(c - a);
  const double length = n.norm();
  if (length < 1e-300) return out;
  n *= 1.0 / length;
  const double s = (x - a).dot(n);
  const double along = relative.dot(n);
  const double before = s - along * p.dt;
  const double side = knownSide != 0 ? knownSide
                      : before > 0   ? 1.0
                      : before < 0   ? -1.0
                                     : (s >= 0 ? 1.0 : -1.0);
  const double distance = s * side - radius;
  const double deepest =
      std::abs(along) * p.dt + (knownSide != 0 ? 5.0 : 1.0) * p.thickness + radius;
  const double ahead = speculative ? std::max(0.0, -along * side) * p.dt : 0.0;
  if (distance >= p.thickness + ahead || distance < -deepest) return out;
  const Vector3d onPlane = x - n * s;
  const auto closest =
      closestPointOnTriangle(msg::toVec3(onPlane), msg::toVec3(a), msg::toVec3(b), msg::toVec3(c));
  const double lateral = p.thickness + radius;
  if ((onPlane - asEigen(closest.point)).squaredNorm() > lateral * lateral) return out;
  out.hit = true;
  out.distance = distance;
  out.gap = (x - asEigen(closest.point)).norm();
  out.normal = n * side;
  out.closest = closest;
  out.side = side > 0 ? 1 : -1;
  return out;
}

/// The part of a that b confirms, per component: the smaller magnitude where both have the same
/// sign, else 0 (what persists over two steps, not a one-step kick).
Vector3d persistent(const Vector3d& a, const Vector3d& b) {
  Vector3d out = Vector3d::Zero();
  for (int k = 0; k < 3; ++k)
    if (a[k] * b[k] > 0) out[k] = std::copysign(std::min(std::abs(a[k]), std::abs(b[k])), a[k]);
  return out;
}

/// The velocity each dynamic rigid will gain over the coming step from its other forces (gravity,
/// a haptic tool's coupling, other interactors' contacts), which the contact force sent now is
/// applied together with: measured from its last two steps, the velocity change not made by
/// this interactor's force (`before`: last step's records; `now`: this step's, sent filled in
/// later; none without `before`). A contact solved without it lets a light rigid pushed by a strong
/// force (a 0.2 kg haptic tool on a 2000 N/m coupling) sink by that force's dt^2 / m every step.
std::map<std::uint64_t, Vector3d> externalDrift(
    const std::map<std::uint64_t, RigidBody>& rigids, const ContactParams& p,
    const std::map<std::uint64_t, ContactMemory::Motion>* before,
    std::map<std::uint64_t, ContactMemory::Motion>& now) {
  std::map<std::uint64_t, Vector3d> out;
  for (const auto& [id, body] : rigids) {
    if (!(body.mass > 0) || !std::isfinite(body.mass)) continue;
    auto& motion = now[id];
    motion.velocity = body.linearVelocity;
    if (!before) continue;
    const auto found = before->find(id);
    if (found == before->end()) continue;
    const Vector3d gained = asEigen(body.linearVelocity) - asEigen(found->second.velocity) -
                            asEigen(found->second.sent);
    motion.external = msg::toVec3(gained / p.dt);
    motion.measured = true;
    if (found->second.measured)
      out[id] = p.dt * persistent(gained / p.dt - asEigen(p.gravity),
                                  asEigen(found->second.external) - asEigen(p.gravity));
  }
  return out;
}

/// Springs touching each node (CSR), to weigh a node with the springs that hold it.
struct Adjacency {
  std::vector<std::size_t> start;
  std::vector<std::size_t> springs;
};
Adjacency adjacency(const Net& net) {
  Adjacency out;
  out.start.assign(net.nodeCount() + 1, 0);
  for (const auto& s : net.springs) {
    ++out.start[s.a + 1];
    ++out.start[s.b + 1];
  }
  for (std::size_t i = 0; i < net.nodeCount(); ++i) out.start[i + 1] += out.start[i];
  out.springs.resize(out.start.back());
  std::vector<std::size_t> fill(out.start.begin(), out.start.end() - 1);
  for (std::size_t k = 0; k < net.springs.size(); ++k) {
    out.springs[fill[net.springs[k].a]++] = k;
    out.springs[fill[net.springs[k].b]++] = k;
  }
  return out;
}

/// The inverse of a node's effective mass for a push along n held for dt: its mass plus
/// springMassWeight * dt^2 times the stiffness of its springs along n (axial k (u.n)^2 plus the
/// tension's transverse stiffness T/L (1 - (u.n)^2)): a node held by its springs does not give
/// way like a free particle within one outer step.
double effectiveInvMass(const Net& net, const Adjacency& adj, std::size_t i, const Vector3d& n,
                        const ContactParams& p) {
  if (net.pinned[i]) return 0.0;
  double stiffness = 0;
  const Vector3d x = positionOf(net, i);
  for (std::size_t k = adj.start[i]; k < adj.start[i + 1]; ++k) {
    const auto& s = net.springs[adj.springs[k]];
    const Vector3d d = positionOf(net, s.a == i ? s.b : s.a) - x;
    const double length = d.norm();
    if (length < 1e-12) continue;
    const double c = d.dot(n) / length;
    const double tension = std::max(0.0, s.stiffness * (length - s.restLength));
    stiffness += s.stiffness * c * c + tension / length * (1 - c * c);
  }
  const double mass = (net.masses[i] + p.springMassWeight * p.dt * p.dt * stiffness);
  return 1.0 / mass;
}

}  // namespace

Status validateContactParams(const ContactParams& p) {
  if (!(p.thickness > 0) || !std::isfinite(p.thickness))
    return makeError("contact: thickness must be finite and > 0");
  if (!(p.beta >= 0 && p.beta <= 1)) return makeError("contact: beta must be in [0, 1]");
  if (!(p.dt > 0) || !std::isfinite(p.dt)) return makeError("contact: dt must be finite and > 0");
  if (!(p.springMassWeight >= 0) || !std::isfinite(p.springMassWeight))
    return makeError("contact: spring mass weight must be >= 0");
  if (p.iterations < 1 || p.iterations > 10000)
    return makeError("contact: iterations must be in [1, 10000]");
  if (!asEigen(p.gravity).allFinite()) return makeError("contact: gravity must be finite");
  return {};
}

TrianglePoint closestPointOnTriangle(const msg::Vec3& point, const msg::Vec3& vertexA,
                                     const msg::Vec3& vertexB, const msg::Vec3& vertexC) {
  const auto p = asEigen(point), a = asEigen(vertexA), b = asEigen(vertexB), c = asEigen(vertexC);
  const Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {vertexA, 1, 0, 0};
  const Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {vertexB, 0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {msg::toVec3(a + ab * v), 1 - v, v, 0};
  }
  const Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {vertexC, 0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {msg::toVec3(a + ac * w), 1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {msg::toVec3(b + (c - b) * w), 0, 1 - w, w};
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {msg::toVec3(a + (ab * v + ac * w)), 1 - v - w, v, w};
}

ContactForces netCollisions(const std::map<std::uint64_t, Net>& nets, const ContactParams& p,
                            ContactMemory* memory) {
  ContactForces out;
  std::map<std::tuple<std::uint64_t, std::uint32_t, std::uint64_t>, int> sides;
  std::map<std::uint64_t, msg::Aabb> boxes;
  std::map<std::uint64_t, Adjacency> adjacent;
  for (const auto& [id, net] : nets) {
    boxes[id] = bounds(net);
    adjacent[id] = adjacency(net);
  }
  for (const auto& [idA, a] : nets) {
    for (const auto& [idB, b] : nets) {
      if (idA == idB || a.nodeCount() == 0 || b.nodeCount() == 0) continue;
      const auto& boxA = boxes[idA];
      const auto& boxB = boxes[idB];
      bool overlap = true;
      const double margin = p.thickness + 1.0;  // nodes up to 1 m/step fast still seen
      for (int k = 0; k < 3; ++k) {
        overlap =
            overlap && boxA.min[k] <= boxB.max[k] + margin && boxB.min[k] <= boxA.max[k] + margin;
      }
      if (!overlap) continue;
      for (std::size_t i = 0; i < a.nodeCount(); ++i) {
        const Vector3d x = positionOf(a, i);
        const Vector3d vi = velocityOf(a, i);
        if (!inBox(x, boxB, p.thickness + vi.lpNorm<1>() * p.dt)) continue;
        const double invA = invMass(a, i);
        if (invA == 0) continue;
        // The nearest feature of net b within the thickness: a triangle, or a node.
        double best = p.thickness;
        Vector3d normal = Vector3d::Zero(), surfaceVelocity = Vector3d::Zero();
        double invB = 0;
        std::size_t tri[3] = {0, 0, 0};
        double weights[3] = {0, 0, 0};
        int featureNodes = 0;
        const auto key = std::tuple{idA, static_cast<std::uint32_t>(i), idB};
        int knownSide = 0;
        if (memory) {
          const auto found = memory->sides.find(key);
          if (found != memory->sides.end()) knownSide = found->second;
        }
        int side = 0;
        if (!b.surface.empty()) {
          double bestGap = 1e300;
          for (std::size_t t = 0; t + 2 < b.surface.size(); t += 3) {
            const std::size_t ia = b.surface[t], ib = b.surface[t + 1], ic = b.surface[t + 2];
            const Vector3d pa = positionOf(b, ia), pb = positionOf(b, ib), pc = positionOf(b, ic);
            const double reach = p.thickness + std::abs(vi[0]) * p.dt + std::abs(vi[1]) * p.dt +
                                 std::abs(vi[2]) * p.dt;
            bool near = true;
            for (int k = 0; k < 3 && near; ++k) {
              near = x[k] >= std::min({pa[k], pb[k], pc[k]}) - reach &&
                     x[k] <= std::max({pa[k], pb[k], pc[k]}) + reach;
            }
            if (!near) continue;
            const Vector3d centre =
                (velocityOf(b, ia) + velocityOf(b, ib) + velocityOf(b, ic)) * (1.0 / 3.0);
            const auto hit = pointTriangle(x, vi - centre, pa, pb, pc, p, knownSide);
            if (!hit.hit || hit.gap >= bestGap) continue;
            bestGap = hit.gap;
            side = hit.side;
            best = hit.distance;
            normal = hit.normal;
            tri[0] = ia, tri[1] = ib, tri[2] = ic;
            weights[0] = hit.closest.wa, weights[1] = hit.closest.wb, weights[2] = hit.closest.wc;
            featureNodes = 3;
          }
        } else {
          for (std::size_t j = 0; j < b.nodeCount(); ++j) {
            const Vector3d d = x - positionOf(b, j);
            const double dist = d.norm();
            if (dist >= best || dist < 1e-12) continue;
            best = dist;
            normal = d * (1.0 / dist);
            tri[0] = j;
            weights[0] = 1;
            featureNodes = 1;
          }
        }
        if (featureNodes == 0) continue;
        if (side != 0) sides[key] = knownSide != 0 ? knownSide : side;
        surfaceVelocity.setZero();
        for (int f = 0; f < featureNodes; ++f) {
          surfaceVelocity += velocityOf(b, tri[f]) * weights[f];
          invB += weights[f] * weights[f] * effectiveInvMass(b, adjacent[idB], tri[f], normal, p);
        }
        const double invNode = effectiveInvMass(a, adjacent[idA], i, normal, p);
        const double vn = (vi - surfaceVelocity).dot(normal);
        const double magnitude = contactMagnitude(best, vn, invNode + invB, p);
        if (magnitude <= 0) continue;
        ++out.contacts;
        const Vector3d f = normal * magnitude;
        addTo(forcesOf(out, idA, a), i, f);
        auto& fb = forcesOf(out, idB, b);
        for (int k = 0; k < featureNodes; ++k) {
          if (!b.pinned[tri[k]]) addTo(fb, tri[k], f * -weights[k]);
        }
      }
    }
  }
  if (memory) memory->sides = std::move(sides);
  return out;
}

ContactForces rigidContacts(const std::map<std::uint64_t, Net>& nets,
                            const std::map<std::uint64_t, RigidBody>& rigids,
                            const ContactParams& p, ContactMemory* memory) {
  ContactForces out;
  ContactMemory next;
  std::map<std::uint64_t, msg::Aabb> netBoxes;
  std::map<std::uint64_t, double> netSpeeds;  // each net's fastest node (1-norm)
  for (const auto& [netId, net] : nets) {
    netBoxes[netId] = bounds(net);
    double fastest = 0;
    for (std::size_t i = 0; i < net.nodeCount(); ++i)
      fastest = std::max(fastest, velocityOf(net, i).lpNorm<1>());
    netSpeeds[netId] = fastest;
  }
  if (memory) next.emptyCalls = memory->emptyCalls, next.started = memory->started;
  if (!next.started) {
    if (nets.empty() && rigids.empty()) ++next.emptyCalls;
    next.started = !(nets.empty() && rigids.empty());
  }
  const bool sequential = memory && next.emptyCalls == 0;
  const auto drift =
      externalDrift(rigids, p, sequential ? &memory->motions : nullptr, next.motions);
  std::vector<detail::RigidNetContact> contacts;
  for (const auto& [rigidId, body] : rigids) {
    const auto box = msg::worldBounds(body.shape, body.position, body.orientation);
    const auto drifting = drift.find(rigidId);
    const Vector3d linear = asEigen(body.linearVelocity) +
                            (drifting != drift.end() ? drifting->second : Vector3d::Zero());
    // Nets whose box (grown by the thickness and one step of the relative motion) misses the
    // rigid's box are skipped.
    const double speed = linear.lpNorm<1>();
    const double spin = asEigen(body.angularVelocity).lpNorm<1>();
    double radius = 0;
    for (int k = 0; k < 3; ++k) radius = std::max(radius, 0.5 * (box.max[k] - box.min[k]));
    auto marginFor = [&](std::uint64_t netId) {
      return p.thickness + (speed + spin * radius + netSpeeds[netId]) * p.dt;
    };
    auto netNear = [&](std::uint64_t netId) {
      const auto& nb = netBoxes[netId];
      const double margin = marginFor(netId);
      for (int k = 0; k < 3; ++k) {
        if (nb.min[k] > box.max[k] + margin || nb.max[k] < box.min[k] - margin) return false;
      }
      return true;
    };
    const bool kinematic = !(body.mass > 0) || !std::isfinite(body.mass);
    auto pointVelocity = [&](const Vector3d& r) -> Vector3d {
      return linear + asEigen(body.angularVelocity).cross(r);
    };
    const auto orientation = asEigen(body.orientation);
    // Nodes against the shape.
    for (const auto& [netId, net] : nets) {
      if (!netNear(netId)) continue;
      const double margin = marginFor(netId);
      for (std::size_t i = 0; i < net.nodeCount(); ++i) {
        const Vector3d x = positionOf(net, i);
        if (!inBox(x, box, margin)) continue;
        if (invMass(net, i) == 0 && kinematic) continue;
        const Vector3d r = x - asEigen(body.position);
        const Vector3d local = orientation.conjugate() * r;
        auto sd = msg::signedDistance(body.shape, msg::toVec3(local));
        const auto key = std::tuple{rigidId, netId, static_cast<std::uint32_t>(i)};
        const ContactMemory::Plane* plane = nullptr;
        if (memory) {
          const auto found = memory->planes.find(key);
          if (found != memory->planes.end()) plane = &found->second;
        }
        if (plane && sd.distance < p.thickness) {
          // A lasting contact: distance to the plane where it began.
          sd.normal = plane->normal;
          sd.distance = local.dot(asEigen(plane->normal)) - plane->offset;
        }
        const Vector3d relative = velocityOf(net, i) - pointVelocity(r);
        // Speculative: a node still apart is a contact if it closes the gap within the step.
        const double ahead = std::max(0.0, -relative.dot(orientation * asEigen(sd.normal))) * p.dt;
        if (sd.distance >= p.thickness + ahead) continue;
        if (!plane && sd.distance < 0) {
          // Inside: take the normal of where the node was one step before, if it was outside then.
          const Vector3d before = r - relative * p.dt;
          const auto sdBefore =
              msg::signedDistance(body.shape, msg::toVec3(orientation.conjugate() * before));
          if (sdBefore.distance > 0) sd.normal = sdBefore.normal;
        }
        if (sd.distance < p.thickness) {
          next.planes[key] =
              plane ? *plane
                    : ContactMemory::Plane{sd.normal, local.dot(asEigen(sd.normal)) - sd.distance};
        }
        detail::RigidNetContact c;
        c.rigidId = rigidId;
        c.netId = netId;
        c.nodes[0] = i;
        c.normal = orientation * asEigen(sd.normal);
        c.r = r;
        c.distance = sd.distance;
        contacts.push_back(c);
      }
    }
    // Corners of boxes, vertices of hulls and meshes, centres of spheres and capsule ends (with
    // their radius) against the nets' triangles.
    std::vector<std::pair<Vector3d, double>> corners;
    const auto& shape = body.shape;
    if (shape.kind == msg::ShapeKind::Box) {
      const auto& h = shape.halfExtents;
      for (int c = 0; c < 8; ++c)
        corners.push_back(
            {Vector3d(c & 1 ? h[0] : -h[0], c & 2 ? h[1] : -h[1], c & 4 ? h[2] : -h[2]), 0.0});
    } else if (shape.kind == msg::ShapeKind::ConvexHull ||
               shape.kind == msg::ShapeKind::TriangleMesh) {
      for (std::size_t v = 0; v + 2 < shape.vertices.size(); v += 3)
        corners.push_back({msg::asVector3(&shape.vertices[v]), 0.0});
    } else if (shape.kind == msg::ShapeKind::Sphere) {
      corners.push_back({Vector3d::Zero(), shape.radius});
    } else if (shape.kind == msg::ShapeKind::Capsule) {
      corners.push_back({Vector3d(0, shape.halfHeight, 0), shape.radius});
      corners.push_back({Vector3d(0, -shape.halfHeight, 0), shape.radius});
    }
    for (const auto& [netId, net] : nets) {
      if (corners.empty() || net.surface.empty() || !netNear(netId)) continue;
      for (const auto& [corner, ball] : corners) {
        const Vector3d r = orientation * corner;
        const Vector3d x = asEigen(body.position) + r;
        const Vector3d vx = pointVelocity(r);
        const double reach = p.thickness + ball + (vx.lpNorm<1>() + netSpeeds[netId]) * p.dt;
        PlaneHit best;
        best.gap = 1e300;
        std::size_t tri[3] = {0, 0, 0};
        for (std::size_t t = 0; t + 2 < net.surface.size(); t += 3) {
          const std::size_t ia = net.surface[t], ib = net.surface[t + 1], ic = net.surface[t + 2];
          const Vector3d pa = positionOf(net, ia), pb = positionOf(net, ib),
                         pc = positionOf(net, ic);
          bool near = true;
          for (int k = 0; k < 3 && near; ++k) {
            near = x[k] >= std::min({pa[k], pb[k], pc[k]}) - reach &&
                   x[k] <= std::max({pa[k], pb[k], pc[k]}) + reach;
          }
          if (!near) continue;
          const Vector3d surface =
              (velocityOf(net, ia) + velocityOf(net, ib) + velocityOf(net, ic)) * (1.0 / 3.0);
          const auto hit = pointTriangle(x, vx - surface, pa, pb, pc, p, 0, ball, true);
          if (!hit.hit || hit.gap >= best.gap) continue;
          best = hit;
          tri[0] = ia, tri[1] = ib, tri[2] = ic;
        }
        if (!best.hit) continue;
        detail::RigidNetContact c;
        c.rigidId = rigidId;
        c.netId = netId;
        c.count = 3;
        const double w[3] = {best.closest.wa, best.closest.wb, best.closest.wc};
        for (int k = 0; k < 3; ++k) c.nodes[k] = tri[k], c.w[k] = w[k];
        // best.normal points to the rigid's side: the triangle is pushed against it. The contact
        // point on the rigid is its surface towards the triangle.
        c.normal = best.normal * -1.0;
        c.r = r + c.normal * ball;
        c.distance = best.distance;
        contacts.push_back(c);
      }
    }
  }
  const auto impulses = detail::solveRigidNetContacts(nets, rigids, drift, contacts, p);
  std::map<std::uint64_t, std::pair<Vector3d, Vector3d>> onRigids;  // force, torque
  for (std::size_t i = 0; i < impulses.shared.size(); ++i) {
    const auto& c = contacts[i];
    const double total = impulses.shared[i] + impulses.locked[i];
    if (total <= 0) continue;
    ++out.contacts;
    auto& [force, torque] =
        onRigids.try_emplace(c.rigidId, Vector3d::Zero(), Vector3d::Zero()).first->second;
    force -= c.normal * (total / p.dt);
    torque -= c.r.cross(c.normal * (total / p.dt));
    if (impulses.shared[i] <= 0) continue;
    const Net& net = nets.at(c.netId);
    const Vector3d f = c.normal * (impulses.shared[i] / p.dt);  // on the net
    auto& forces = forcesOf(out, c.netId, net);
    for (int k = 0; k < c.count; ++k) {
      if (invMass(net, c.nodes[k]) > 0) addTo(forces, c.nodes[k], f * c.w[k]);
    }
  }
  for (const auto& [rigidId, sum] : onRigids) {
    const auto& body = rigids.at(rigidId);
    if (!(body.mass > 0) || !std::isfinite(body.mass)) continue;
    out.rigidForces[rigidId] =
        msg::ForceEvent{msg::toVec3(sum.first), msg::toVec3(sum.second), body.position, p.dt};
    if (const auto motion = next.motions.find(rigidId); motion != next.motions.end())
      motion->second.sent = msg::toVec3(sum.first * (p.dt / body.mass));
  }
  if (memory) *memory = std::move(next);
  return out;
}

}  // namespace vrflow::massspring

namespace vrflow::massspring {

void addUserContacts(const std::map<std::uint64_t, Net>& nets,
                     const std::map<std::uint64_t, const camera::UserSurface*>& users,
                     const ContactParams& p, ContactForces& out, UserContactMemory* memory) {
  UserContactMemory next;
  // The user cannot give way: the node must be out of it by the end of the step, the whole
  // overlap removed at once, against the full stiffness of the node's springs (the backward
  // Euler weight of a node held by springs). The soft defaults let a hand pass through a net.
  ContactParams userParams = p;
  userParams.beta = 1.0;
  userParams.springMassWeight = 1.0;
  for (const auto& [userId, user] : users) {
    for (const auto& [netId, net] : nets) {
      const msg::Aabb netBox = bounds(net);
      bool near = true;
      for (int k = 0; k < 3; ++k)
        near = near && netBox.min[k] <= user->bounds.max[k] + p.thickness + user->spacing &&
               netBox.max[k] >= user->bounds.min[k] - p.thickness - user->spacing;
      if (!near) continue;
      const std::vector<msg::Vec3>* before = nullptr;
      if (memory) {
        const auto found = memory->entrySides.find({userId, netId});
        if (found != memory->entrySides.end() && found->second.size() == net.nodeCount())
          before = &found->second;
      }
      auto& sides = next.entrySides[{userId, netId}];
      sides.assign(net.nodeCount(), msg::Vec3{});
      const Adjacency adj = adjacency(net);
      for (std::size_t i = 0; i < net.nodeCount(); ++i) {
        if (net.pinned[i]) continue;
        const Vector3d x = positionOf(net, i);
        // Nodes within a voxel step of the user's box are watched, so that one the user's next
        // step swallows has its side remembered.
        if (!inBox(x, user->bounds, p.thickness + user->spacing)) continue;
        const double distance = user->distance(msg::toVec3(x));
        Vector3d n = asEigen(user->normal(msg::toVec3(x)));
        if (n.isZero(0.0)) continue;
        const Vector3d entered = before ? Vector3d(asEigen((*before)[i])) : Vector3d::Zero();
        if (distance >= 0) {
          sides[i] = msg::toVec3(n);
        } else if (!entered.isZero(0.0)) {
          // Inside: out of the side it came from, which it keeps until it is out again.
          if (n.dot(entered) < 0) n = entered;
          sides[i] = msg::toVec3(entered);
        }
        // Contacts only within the thickness of the user's box (its distance field is offset by
        // half a voxel, so the box is what bounds the contacts).
        if (distance >= p.thickness || !inBox(x, user->bounds, p.thickness)) continue;
        // The user is infinitely heavy and moves with its surface velocity.
        const Vector3d relative = velocityOf(net, i) - asEigen(user->velocityAt(msg::toVec3(x)));
        const double f = contactMagnitude(distance, relative.dot(n),
                                          effectiveInvMass(net, adj, i, n, userParams), userParams);
        if (f <= 0) continue;
        addTo(forcesOf(out, netId, net), i, n * f);
        ++out.contacts;
      }
    }
  }
  if (memory) *memory = std::move(next);
}

}  // namespace vrflow::massspring
