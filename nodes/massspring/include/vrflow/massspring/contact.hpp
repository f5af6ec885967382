#pragma once

#include <cstdint>
#include <map>
#include <vector>

#include "vrflow/massspring/net.hpp"
#include "vrflow/message/shape.hpp"

// Contacts of net nodes with other nets' surfaces and with rigid shapes.
//
// Response (both kinds): a node closer than `thickness` to a surface gets a repulsive force along
// the surface normal n, of size
//   f = max(0, (-vn + beta * (thickness - d) / dt) / (dt * (1/m_node + 1/m_other)))
// where d is the distance, vn the relative normal velocity (node minus surface point) and m_other
// the other side's mass (a rigid's mass; for a net triangle, its nodes' masses weighted by the
// barycentric coordinates; pinned nodes and kinematic rigids are infinitely heavy). That is the
// impulse that stops the approach within one outer step plus a fraction beta of the overlap, as a
// force held for dt: stable at any dt, no stiffness to tune. The other side gets the opposite force.

namespace vrflow::massspring {

struct ContactParams {
  double thickness = 0.02;  ///< contact distance (m), > 0
  double beta = 0.2;        ///< fraction of the overlap removed per step, in [0, 1]
  double dt = 0.01;         ///< the outer step the forces are held for (s), > 0
  double nodeMassScale = 1.0;  ///< nodes weigh this many times their mass in the response, >= 1
};
Status validateContactParams(const ContactParams& params);

/// A rigid body as the interactors see it (from a rigid object and its shape resource).
struct RigidBody {
  msg::Vec3 position{};
  msg::Quat orientation{0, 0, 0, 1};
  msg::Vec3 linearVelocity{};
  msg::Vec3 angularVelocity{};
  double mass = 0.0;  ///< <= 0 or infinite: kinematic (infinitely heavy)
  msg::Shape shape;
};

/// Forces on nets (xyz per node, keyed by net id) and on rigids (one ForceEvent per touched
/// rigid: the sum of its contact forces at its centre of mass `position`, with the torque of
/// those forces about it; duration dt).
struct ContactForces {
  std::map<std::uint64_t, std::vector<double>> nodeForces;
  std::map<std::uint64_t, msg::ForceEvent> rigidForces;
  std::size_t contacts = 0;
};

/// Nodes of every net against the surface triangles of every other net (nets without a surface
/// are seen as their nodes: node/node repulsion). Nets are visited in id order (deterministic).
ContactForces netCollisions(const std::map<std::uint64_t, Net>& nets, const ContactParams& params);

/// Nodes of every net against every rigid shape (signedDistance in the body frame).
ContactForces rigidContacts(const std::map<std::uint64_t, Net>& nets,
                            const std::map<std::uint64_t, RigidBody>& rigids,
                            const ContactParams& params);

/// Closest point of triangle abc to p, with its barycentric weights (Ericson's algorithm).
struct TrianglePoint {
  msg::Vec3 point{};
  double wa = 0, wb = 0, wc = 0;
};
TrianglePoint closestPointOnTriangle(const msg::Vec3& p, const msg::Vec3& a, const msg::Vec3& b, const msg::Vec3& c);

}  // namespace vrflow::massspring
