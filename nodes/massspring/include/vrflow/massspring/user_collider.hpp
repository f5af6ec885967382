#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <vector>

#include "vrflow/camera/user_surface.hpp"
#include "vrflow/massspring/net.hpp"

// The captured user (nodes/camera's UserSurface: signed distance field and surface velocity) as a
// kinematic collider inside the net's sub-steps, a position constraint like the maximum stretch.
//
// After a sub-step's integration, every free node closer than `thickness` to the user's surface
// goes out along the field's gradient to that distance; its velocity relative to the user's
// surface velocity there loses its approaching normal part (inelastic), and its tangential part
// loses at most `friction` times that normal change (Coulomb). The user is infinitely heavy:
// nothing pushes it. A node is tested along its path over the sub-step (continuous), so a fast
// node cannot cross a thin hand between two sub-steps, and a node remembers the side it was last
// outside on (a voxel hull moves by whole voxels and can swallow a node past the middle of a
// hand, where the gradient points out of the far side): it goes out of the side it came from.
// The net's surface between the nodes is tested too (each triangle's centroid and edge middles;
// a point inside moves its triangle's nodes by their barycentric weights, inverse-mass weighted),
// so a hand narrower than the net's spacing cannot pass between the nodes.
// A voxel hull moves by whole frames: with the frame before given, the field the sub-steps see
// sweeps from that frame to the last one over the outer step (the two distance fields blended),
// so a moving hand pushes the net a little every sub-step, not its whole frame's motion in the
// first one (which, through the springs' limits, threw the paper net's nodes at up to 43 m/s
// under a hand moving at 1.3 m/s). The net therefore meets the user one frame late. The surface
// velocity is the last frame's.

namespace vrflow::massspring {

/// The collider's settings.
struct UserColliderParams {
  double thickness = 0.02;  ///< distance kept between a node and the user's surface (m), > 0
  double friction = 0.5;    ///< Coulomb coefficient between the net and the user, >= 0
};
Status validateUserColliderParams(const UserColliderParams& params);

/// What the collider keeps between sub-steps and steps: for each user, each node's outward normal
/// the last time it was near the user and outside it (zero: not seen).
struct UserColliderMemory {
  std::map<std::uint64_t, std::vector<msg::Vec3>> sides;
};

/// The users a net collides with inside its sub-steps (step()).
struct UserColliders {
  std::map<std::uint64_t, const camera::UserSurface*> users;  ///< by id, ready fields only
  /// The frame before each user's last one, by id (may be empty: the last frame is held).
  std::map<std::uint64_t, const camera::UserSurface*> previous;
  UserColliderParams params;
  UserColliderMemory* memory = nullptr;  ///< keep one per net across steps; may be null
};

/// Projects the net's free nodes out of every user (in id order), `before` holding the nodes'
/// positions at the start of the sub-step (xyz per node; empty: no path test), `blend` where the
/// field is between the frame before (0) and the last one (1). Returns how many points (nodes and
/// surface points) were projected.
std::size_t collideWithUsers(Net& net, std::span<const double> before,
                             const UserColliders& colliders, double blend = 1.0);

}  // namespace vrflow::massspring
