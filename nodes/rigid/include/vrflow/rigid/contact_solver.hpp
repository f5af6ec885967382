#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/camera/user_surface.hpp"
#include "vrflow/message/object_type.hpp"  // before values.hpp, or -Wshadow
#include "vrflow/message/values.hpp"
#include "vrflow/rigid/body.hpp"
#include "vrflow/rigid/contact_defaults.hpp"

// The rigid interactor's solver: Bullet finds the contacts (btCollisionWorld with a
// btDbvtBroadphase and btCollisionDispatcher; persistent manifolds), then our own sequential
// impulse solver (friction, restitution, warm starting, Baumgarte position correction,
// speculative contacts) computes per-body impulses. They are returned as force events
// (force = impulse / dt, torque = angular impulse / dt, duration = dt, point = the body's centre
// of mass) so that the animator, which applies them on its next step, stays the only writer of
// state. Bullet's headers stay inside the implementation.

namespace vrflow::rigid {

/// The solver's settings. The defaults of the fields that the interactor's manifest declares
/// (gravity to slop) are the manifest's, generated into contact_defaults.hpp.
struct ContactParams {
  /// External acceleration every dynamic body receives during the step (the force field's
  /// gravity): the solver predicts v + g dt before solving, so resting contact holds.
  Vec3 gravity{manifest_defaults::kGravityX, manifest_defaults::kGravityY,
               manifest_defaults::kGravityZ};
  /// Coefficient of restitution and Coulomb friction of a body that has none of its own
  /// (Body::restitution, Body::friction negative).
  double restitution = manifest_defaults::kRestitution;
  double friction = manifest_defaults::kFriction;
  /// closing speeds (m/s) below this do not bounce
  double restitutionThreshold = manifest_defaults::kRestitutionThreshold;
  int iterations = manifest_defaults::kIterations;  ///< sequential impulse iterations
  double baumgarte =
      manifest_defaults::kBaumgarte;       ///< fraction of the penetration removed per step
  double slop = manifest_defaults::kSlop;  ///< penetration (m) left alone, keeps contacts alive
  double margin = 0.005;                   ///< Bullet collision margin of hull shapes (m)
  /// Rolling and spinning resistance (m): a contact where a sphere or a capsule takes part resists
  /// relative rotation with a torque of at most this times the normal force, so that they come to
  /// rest (flat-faced shapes need none: their face contacts stop rolling).
  double rollingFriction = 0.01;
  /// Contacts are found up to this gap (m) and solved speculatively (approach allowed up to the
  /// gap): catches objects moving up to about this far per step against each other.
  double speculativeDistance = 0.04;
  bool warmStart = true;
  /// Contacts with a captured user (user_contacts.hpp). A visual hull is fatter than the body it
  /// films and moves in whole-voxel steps, so a body can start inside it and its estimated surface
  /// velocity is noisy. The position correction of a user contact pushes out at most this fast
  /// (m/s; Box2D's maximum linear correction as a speed): a body found inside is moved out gently
  /// over a few steps, not launched.
  double userPushOut = 0.5;
  /// The user's surface velocity at a contact is taken at most this fast (m/s): a human hand, not
  /// a voxel step per frame.
  double userSurfaceSpeed = 3.0;
};

/// The friction of a pair: the geometric mean sqrt(fa fb) of its bodies' (Box2D's and Bullet's
/// rule: ice on anything slides), a negative value standing for `fallback`.
double combinedFriction(double a, double b, double fallback);
/// The restitution of a pair: the larger of its bodies' (Box2D's rule: a rubber ball bounces on
/// any floor), a negative value standing for `fallback`.
double combinedRestitution(double a, double b, double fallback);

/// One contact point found in the last solve (for tests and diagnostics).
struct ContactInfo {
  std::uint64_t a = 0, b = 0;
  Vec3 point{};         ///< on b, world frame
  Vec3 normal{};        ///< from b to a
  double distance = 0;  ///< negative when penetrating
};

class RigidContactSolver {
 public:
  explicit RigidContactSolver(ContactParams params = {});
  ~RigidContactSolver();
  RigidContactSolver(const RigidContactSolver&) = delete;
  RigidContactSolver& operator=(const RigidContactSolver&) = delete;

  const ContactParams& params() const { return params_; }
  void setParams(const ContactParams& params) { params_ = params; }

  /// Adds a body or replaces its state (a new shape rebuilds its collision object).
  Status setBody(const Body& body);
  /// Updates the pose and velocities of a known body (false if unknown).
  bool setState(std::uint64_t id, const Vec3& position, const Quat& orientation,
                const Vec3& linearVelocity, const Vec3& angularVelocity);
  void removeBody(std::uint64_t id);
  bool contains(std::uint64_t id) const;
  std::size_t size() const;

  /// The captured users the bodies collide with (user_contacts.hpp), as solids of infinite mass
  /// moving with their surface velocity; they must outlive the next solve(). Empty: none.
  void setUsers(std::map<std::uint64_t, const camera::UserSurface*> users) {
    users_ = std::move(users);
  }

  /// Collision detection on the current local copy, then the impulse solve over dt. Returns a
  /// force event per dynamic body that receives a non-zero impulse, ordered by id.
  std::vector<std::pair<std::uint64_t, msg::ForceEvent>> solve(double dt);

  /// The contacts of the last solve(), ordered by body ids.
  const std::vector<ContactInfo>& contacts() const { return contacts_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  ContactParams params_;
  std::vector<ContactInfo> contacts_;
  std::map<std::uint64_t, const camera::UserSurface*> users_;
};

}  // namespace vrflow::rigid
