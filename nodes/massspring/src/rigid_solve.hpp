#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <map>
#include <vector>

#include "vrflow/massspring/contact.hpp"

// The velocity solve behind rigidContacts (internal to the library): the contacts between rigids
// and nets' nodes, the nets' springs and maximum-stretch limits, solved together by sequential
// impulses (projected Gauss-Seidel) over one outer step.

namespace vrflow::massspring::detail {

/// The fastest an overlap is pushed out (m/s): faster, the push-out adds energy (a bounce).
inline constexpr double kMaxPushSpeed = 0.1;

/// One rigid / net contact: a node (count 1) or a point of a net triangle (count 3, barycentric
/// weights w) against a point of a rigid.
struct RigidNetContact {
  std::uint64_t rigidId = 0;
  std::uint64_t netId = 0;
  std::size_t nodes[3] = {0, 0, 0};
  double w[3] = {1, 0, 0};
  int count = 1;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< pushes the net along it, the rigid back
  Eigen::Vector3d r = Eigen::Vector3d::Zero();  ///< contact point minus the rigid's centre (world)
  double distance = 0;  ///< signed gap along the normal (the contact surface is at thickness)
};

/// The normal impulses (N s, >= 0, one per contact) over the outer step p.dt: `shared` acts on
/// both sides, `locked` on the rigid only (what a net locked at its limits hands to its pins).
struct ContactImpulses {
  std::vector<double> shared;
  std::vector<double> locked;
};

/// The impulses such that after the step no contact approaches faster than it closes its gap to
/// the thickness (speculative contacts: a contact still apart may close its gap within the step,
/// no more; an overlap is pushed out by beta of it per step, at most kMaxPushSpeed), with the
/// rigids' masses and inertias, the nodes' masses, the nets' springs (implicit: the spring force
/// at the end of the step) and their maximum-stretch limits (at the end-of-step positions) in one
/// solve. Pinned nodes and kinematic rigids are infinitely heavy. A rigid moves over the step at
/// its velocity plus its `drift` (what its other forces add; none if absent). Deterministic: a
/// fixed order, p.iterations sweeps.
ContactImpulses solveRigidNetContacts(const std::map<std::uint64_t, Net>& nets,
                                      const std::map<std::uint64_t, RigidBody>& rigids,
                                      const std::map<std::uint64_t, Eigen::Vector3d>& drift,
                                      const std::vector<RigidNetContact>& contacts,
                                      const ContactParams& p);

}  // namespace vrflow::massspring::detail
