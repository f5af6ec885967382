#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "vrflow/camera/user_copy.hpp"
#include "vrflow/massspring/contact.hpp"
#include "vrflow/massspring/net.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/reader.hpp"

// Nets and rigids as massspring / rigid object chunks.

namespace vrflow::massspring {

/// Adds an object chunk for net `id`: with `full`, an Add with every parameter (positions,
/// velocities, masses, pinned, springs, bounds, surface); else an Update with positions,
/// velocities and bounds (what changes while the net moves).
void writeNet(msg::MessageBuilder& builder, std::uint64_t id, const Net& net, bool full);

/// An interactor's local copy of the objects it reads: nets, rigids and their shape resources,
/// kept up to date from object chunks (add / update / delete) and static shape resources.
class SceneCopy {
 public:
  /// Applies every massspring and rigid object chunk and every Raw resource named as a rigid's
  /// shape. A chunk that cannot be decoded (bad springs bytes, a shape that does not decode, a
  /// net whose sizes disagree) is an error; the copy keeps what it had for that object.
  Status apply(const msg::MessageView& message);

  const std::map<std::uint64_t, Net>& nets() const { return nets_; }
  /// The rigids whose shape resource has arrived.
  std::map<std::uint64_t, RigidBody> rigids() const;
  /// The captured users (type `user`) whose distance field has arrived.
  std::map<std::uint64_t, const camera::UserSurface*> users() const { return users_.ready(); }
  /// The capture iteration of the users' last frame (camera::UserCopy::captureIteration).
  std::optional<std::int64_t> userCaptureIteration() const { return users_.captureIteration(); }

 private:
  struct RigidEntry {
    RigidBody body;
    std::uint64_t shapeId = 0;
  };
  std::map<std::uint64_t, Net> nets_;
  std::map<std::uint64_t, RigidEntry> rigids_;
  std::map<std::uint64_t, msg::Shape> shapes_;
  camera::UserCopy users_;
};

}  // namespace vrflow::massspring
