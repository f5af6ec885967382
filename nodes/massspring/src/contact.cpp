#include "vrflow/massspring/contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vrflow::massspring {
namespace {

msg::Vec3 sub(const msg::Vec3& a, const msg::Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
msg::Vec3 add(const msg::Vec3& a, const msg::Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
msg::Vec3 scale(const msg::Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const msg::Vec3& a, const msg::Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
msg::Vec3 cross(const msg::Vec3& a, const msg::Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

double invMass(const Net& net, std::size_t i) { return net.pinned[i] ? 0.0 : 1.0 / net.masses[i]; }

void addTo(std::vector<double>& forces, std::size_t node, const msg::Vec3& f) {
  for (int k = 0; k < 3; ++k) forces[3 * node + k] += f[k];
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

bool inBox(const msg::Vec3& p, const msg::Aabb& box, double margin) {
  for (int k = 0; k < 3; ++k) {
    if (p[k] < box.min[k] - margin || p[k] > box.max[k] + margin) return false;
  }
  return true;
}

}  // namespace

Status validateContactParams(const ContactParams& p) {
  if (!(p.thickness > 0) || !std::isfinite(p.thickness)) return makeError("contact: thickness must be finite and > 0");
  if (!(p.beta >= 0 && p.beta <= 1)) return makeError("contact: beta must be in [0, 1]");
  if (!(p.dt > 0) || !std::isfinite(p.dt)) return makeError("contact: dt must be finite and > 0");
  return {};
}

TrianglePoint closestPointOnTriangle(const msg::Vec3& p, const msg::Vec3& a, const msg::Vec3& b, const msg::Vec3& c) {
  const msg::Vec3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return {a, 1, 0, 0};
  const msg::Vec3 bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return {b, 0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {add(a, scale(ab, v)), 1 - v, v, 0};
  }
  const msg::Vec3 cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return {c, 0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {add(a, scale(ac, w)), 1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {add(b, scale(sub(c, b), w)), 0, 1 - w, w};
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {add(a, add(scale(ab, v), scale(ac, w))), 1 - v - w, v, w};
}

ContactForces netCollisions(const std::map<std::uint64_t, Net>& nets, const ContactParams& p) {
  ContactForces out;
  std::map<std::uint64_t, msg::Aabb> boxes;
  for (const auto& [id, net] : nets) boxes[id] = bounds(net);
  for (const auto& [idA, a] : nets) {
    for (const auto& [idB, b] : nets) {
      if (idA == idB || a.nodeCount() == 0 || b.nodeCount() == 0) continue;
      const auto& boxA = boxes[idA];
      const auto& boxB = boxes[idB];
      bool overlap = true;
      for (int k = 0; k < 3; ++k) {
        overlap = overlap && boxA.min[k] <= boxB.max[k] + p.thickness && boxB.min[k] <= boxA.max[k] + p.thickness;
      }
      if (!overlap) continue;
      for (std::size_t i = 0; i < a.nodeCount(); ++i) {
        const msg::Vec3 x = a.position(i);
        if (!inBox(x, boxB, p.thickness)) continue;
        const double invA = invMass(a, i);
        if (invA == 0) continue;
        // The nearest feature of net b within the thickness: a triangle, or a node.
        double best = p.thickness;
        msg::Vec3 normal{}, surfaceVelocity{};
        double invB = 0;
        std::size_t tri[3] = {0, 0, 0};
        double weights[3] = {0, 0, 0};
        int featureNodes = 0;
        if (!b.surface.empty()) {
          for (std::size_t t = 0; t + 2 < b.surface.size(); t += 3) {
            const std::size_t ia = b.surface[t], ib = b.surface[t + 1], ic = b.surface[t + 2];
            const auto pa = b.position(ia), pb = b.position(ib), pc = b.position(ic);
            bool near = true;
            for (int k = 0; k < 3 && near; ++k) {
              near = x[k] >= std::min({pa[k], pb[k], pc[k]}) - best && x[k] <= std::max({pa[k], pb[k], pc[k]}) + best;
            }
            if (!near) continue;
            const auto cp = closestPointOnTriangle(x, pa, pb, pc);
            const msg::Vec3 d = sub(x, cp.point);
            const double dist = std::sqrt(dot(d, d));
            if (dist >= best) continue;
            msg::Vec3 n;
            if (dist > 1e-12) {
              n = scale(d, 1.0 / dist);
            } else {
              n = cross(sub(pb, pa), sub(pc, pa));
              const double len = std::sqrt(dot(n, n));
              if (len < 1e-300) continue;
              n = scale(n, 1.0 / len);
            }
            best = dist;
            normal = n;
            tri[0] = ia, tri[1] = ib, tri[2] = ic;
            weights[0] = cp.wa, weights[1] = cp.wb, weights[2] = cp.wc;
            featureNodes = 3;
          }
        } else {
          for (std::size_t j = 0; j < b.nodeCount(); ++j) {
            const msg::Vec3 d = sub(x, b.position(j));
            const double dist = std::sqrt(dot(d, d));
            if (dist >= best || dist < 1e-12) continue;
            best = dist;
            normal = scale(d, 1.0 / dist);
            tri[0] = j;
            weights[0] = 1;
            featureNodes = 1;
          }
        }
        if (featureNodes == 0) continue;
        surfaceVelocity = {0, 0, 0};
        double massB = 0;
        bool pinnedB = false;
        for (int f = 0; f < featureNodes; ++f) {
          surfaceVelocity = add(surfaceVelocity, scale(b.velocity(tri[f]), weights[f]));
          massB += weights[f] * b.masses[tri[f]];
          pinnedB = pinnedB || (b.pinned[tri[f]] && weights[f] > 0.5);
        }
        invB = pinnedB || massB <= 0 ? 0.0 : 1.0 / massB;
        const double vn = dot(sub(a.velocity(i), surfaceVelocity), normal);
        const double magnitude = contactMagnitude(best, vn, invA + invB, p);
        if (magnitude <= 0) continue;
        ++out.contacts;
        const msg::Vec3 f = scale(normal, magnitude);
        addTo(forcesOf(out, idA, a), i, f);
        auto& fb = forcesOf(out, idB, b);
        for (int k = 0; k < featureNodes; ++k) {
          if (!b.pinned[tri[k]]) addTo(fb, tri[k], scale(f, -weights[k]));
        }
      }
    }
  }
  return out;
}

ContactForces rigidContacts(const std::map<std::uint64_t, Net>& nets, const std::map<std::uint64_t, RigidBody>& rigids,
                            const ContactParams& p) {
  ContactForces out;
  for (const auto& [rigidId, body] : rigids) {
    const auto box = msg::worldBounds(body.shape, body.position, body.orientation);
    const bool kinematic = !(body.mass > 0) || !std::isfinite(body.mass);
    const double invRigid = kinematic ? 0.0 : 1.0 / body.mass;
    msg::Vec3 totalForce{}, totalTorque{};
    bool touched = false;
    for (const auto& [netId, net] : nets) {
      for (std::size_t i = 0; i < net.nodeCount(); ++i) {
        const msg::Vec3 x = net.position(i);
        if (!inBox(x, box, p.thickness)) continue;
        const double invNode = invMass(net, i);
        if (invNode + invRigid == 0) continue;
        const msg::Vec3 r = sub(x, body.position);
        const auto sd = msg::signedDistance(body.shape, msg::rotateInverse(body.orientation, r));
        if (sd.distance >= p.thickness) continue;
        const msg::Vec3 normal = msg::rotate(body.orientation, sd.normal);
        const msg::Vec3 pointVelocity = add(body.linearVelocity, cross(body.angularVelocity, r));
        const double vn = dot(sub(net.velocity(i), pointVelocity), normal);
        const double magnitude = contactMagnitude(sd.distance, vn, invNode / p.nodeMassScale + invRigid, p);
        if (magnitude <= 0) continue;
        ++out.contacts;
        const msg::Vec3 f = scale(normal, magnitude);
        if (invNode > 0) addTo(forcesOf(out, netId, net), i, f);
        totalForce = sub(totalForce, f);
        totalTorque = sub(totalTorque, cross(r, f));
        touched = true;
      }
    }
    if (touched && !kinematic) out.rigidForces[rigidId] = msg::ForceEvent{totalForce, totalTorque, body.position, p.dt};
  }
  return out;
}

}  // namespace vrflow::massspring
