#pragma once
// An interactor's copy of the `user` objects it receives (builtin_types.hpp's userType()): the
// parameters of their add and update chunks and the dynamic distance and velocity field
// resources they name, kept from message to message.

#include <cstdint>
#include <map>
#include <optional>

#include "vrflow/base/result.hpp"
#include "vrflow/camera/user_surface.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::camera {

/// The users seen so far, by id.
class UserCopy {
 public:
  /// Applies the message's user object chunks, then the ScalarField and VectorField resources
  /// a user names (sdf, velocityField). A field whose kind or size does not fit is an error
  /// naming the user and the resource; the copy keeps what it had for that user.
  Status apply(const msg::MessageView& message);

  /// The capture iteration (capture_stamps.hpp) of the last message that brought a user object,
  /// nullopt before one or when it carried none: which frame the interactor now sees.
  std::optional<std::int64_t> captureIteration() const { return captureIteration_; }

  /// Every user whose distance field has arrived, by id.
  std::map<std::uint64_t, const UserSurface*> ready() const;
  const std::map<std::uint64_t, UserSurface>& all() const { return users_; }

 private:
  struct Ids {
    std::uint64_t sdf = 0, velocity = 0;
  };
  std::map<std::uint64_t, UserSurface> users_;
  std::map<std::uint64_t, Ids> ids_;
  std::optional<std::int64_t> captureIteration_;
};

}  // namespace vrflow::camera
