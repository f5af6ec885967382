#pragma once

#include <cstdint>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

#include "vrflow/camera/user_surface.hpp"
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
// force held for dt: stable at any dt, no stiffness to tune. The other side gets the opposite
// force.

namespace vrflow::massspring {

struct ContactParams {
  double thickness = 0.02;  ///< contact distance (m), > 0
  double beta = 0.2;        ///< fraction of the overlap removed per step, in [0, 1]
  double dt = 0.01;         ///< the outer step the forces are held for (s), > 0
  /// Net / net and user contacts: a node weighs its mass plus springMassWeight * dt^2 *
  /// (stiffness of its springs along the contact normal), since a node held by stiff springs does
  /// not give way like a free particle within one outer step. 0: free particles; large values
  /// overshoot. (Rigid contacts solve with the springs themselves and do not use it.)
  double springMassWeight = 0.01;
  /// Rigid contacts: sequential-impulse sweeps of their velocity solve, in [1, 10000].
  int iterations = 30;
  /// Rigid contacts: the acceleration of the field that pulls the rigids and the nets' nodes
  /// alike (m/s^2). A rigid's other forces count in its contacts only as far as they differ from
  /// it (rigidContacts).
  msg::Vec3 gravity{0, -9.81, 0};
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

/// What the contact functions remember between steps. netCollisions: for each (net, node, other
/// net) in contact, the side (+1/-1 along the other net's triangle normals) the node came from,
/// kept while the contact lasts. rigidContacts: for each (rigid, net, node) in contact, the
/// body-frame plane (outward normal, offset) of the surface where the contact began. While the
/// contact lasts, the node is pushed out along that plane, so a node that went deep into a shape
/// is never pushed out through the far side. Keep one per interactor; pass it every step.
struct ContactMemory {
  struct Plane {
    msg::Vec3 normal{};
    double offset = 0.0;
  };
  std::map<std::tuple<std::uint64_t, std::uint64_t, std::uint32_t>, Plane> planes;
  std::map<std::tuple<std::uint64_t, std::uint32_t, std::uint64_t>, int> sides;
  /// rigidContacts: each touched or nearby dynamic rigid's velocity when last seen, the velocity
  /// change the contact force sent to it then gives it over a step, and the acceleration the
  /// other forces on it (gravity, a haptic tool's coupling, other contacts) gave it over the step
  /// before (see rigidContacts).
  struct Motion {
    msg::Vec3 velocity{};
    msg::Vec3 sent{};
    msg::Vec3 external{};
    bool measured = false;  ///< external holds a measurement
  };
  std::map<std::uint64_t, Motion> motions;
  /// Calls before the first that saw a rigid or a net: an initial message on the interactor's
  /// objects (states one iteration old) shows as one empty call. The measurement above needs
  /// the sequential wiring (0): it is off otherwise.
  int emptyCalls = 0;
  bool started = false;
};

/// Nodes of every net against the surface triangles of every other net (nets without a surface
/// are seen as their nodes: node/node repulsion). Nets are visited in id order (deterministic).
/// A node's side of a triangle is the side it was on one step before (x - v_rel dt), so a node
/// that crossed a triangle within one step is pushed back, not through.
ContactForces netCollisions(const std::map<std::uint64_t, Net>& nets, const ContactParams& params,
                            ContactMemory* memory = nullptr);

/// Rigid / net contacts, solved with the nets' nodes in one velocity solve (sequential impulses,
/// as Box2D and Bullet solve soft / rigid contact). Detection: nodes of every net against every
/// rigid shape (signed distance in the body frame), and the vertices of box, hull and mesh shapes
/// and the centres of spheres and capsule ends (with their radius) against every net's surface
/// triangles, so that a corner or a small ball cannot slip between nodes. Detection is
/// speculative (continuous in the normal direction): a pair still apart is a contact when it
/// closes its gap within the step (gap < thickness + approach speed * dt). Response: the normal
/// impulses that leave no contact approaching faster than it may close its gap to the thickness
/// (and push an overlap out by beta of it per step), with the rigid's mass and inertia, the
/// contacted nodes' masses, and every spring and maximum-stretch limit of the contacted nets in
/// the same solve (`iterations` sweeps), so the net's stiffness and pins hold the rigid, not the
/// contacted nodes' inertia alone. Only the contact impulses leave the solve, as forces held for
/// dt: node forces, and one ForceEvent per touched rigid (sum at its centre of mass, torque about
/// it). Rigids, nets and contacts in id order (deterministic).
ContactForces rigidContacts(const std::map<std::uint64_t, Net>& nets,
                            const std::map<std::uint64_t, RigidBody>& rigids,
                            const ContactParams& params, ContactMemory* memory = nullptr);

/// What addUserContacts keeps between steps: for each (user, net) pair, the user's outward
/// normal at each node the last time the node was near the user and outside it (zero: not seen).
/// A captured user moves by voxel steps, so a thin hand can swallow a node in one step, past the
/// middle of its thickness; the distance field's gradient then points out of the far side and
/// would push the node through. The remembered normal says which side the node came from.
struct UserContactMemory {
  std::map<std::pair<std::uint64_t, std::uint64_t>, std::vector<msg::Vec3>> entrySides;
};

/// Nodes of every net against every captured user (nodes/camera: its distance field and surface
/// velocity): the header's response with the user infinitely heavy, a node's relative velocity
/// taken against the user's surface velocity where it is. A node inside the user whose gradient
/// points away from the side it entered by (`memory`) is pushed back out of that side. Node
/// forces only: nothing pushes the user. Users and nets in id order. The forces are added to
/// `out`'s node forces.
void addUserContacts(const std::map<std::uint64_t, Net>& nets,
                     const std::map<std::uint64_t, const camera::UserSurface*>& users,
                     const ContactParams& params, ContactForces& out,
                     UserContactMemory* memory = nullptr);

/// Closest point of triangle abc to p, with its barycentric weights (Ericson's algorithm).
struct TrianglePoint {
  msg::Vec3 point{};
  double wa = 0, wb = 0, wc = 0;
};
TrianglePoint closestPointOnTriangle(const msg::Vec3& p, const msg::Vec3& a, const msg::Vec3& b,
                                     const msg::Vec3& c);

}  // namespace vrflow::massspring
