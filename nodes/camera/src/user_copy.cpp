#include "vrflow/camera/user_copy.hpp"

#include <span>
#include <string>

#include "vrflow/camera/capture_stamps.hpp"
#include "vrflow/message/builtin_types.hpp"

namespace vrflow::camera {

Status UserCopy::apply(const msg::MessageView& message) {
  using P = msg::UserParam;
  const auto userType = msg::userType().id();
  Status result;
  auto fail = [&](std::string text) {
    if (result) result = makeError(std::move(text));
  };
  // Objects first: a user's first message carries its fields before its add chunk.
  for (const auto chunk : message) {
    const auto object = chunk.asObject();
    if (!object || object->typeId() != userType) continue;
    captureIteration_ = int64Stamp(message, kCaptureIterationStamp);
    if (object->op() == msg::ObjectOp::Delete) {
      users_.erase(object->id());
      ids_.erase(object->id());
      continue;
    }
    UserSurface& user = users_[object->id()];
    user.id = object->id();
    Ids& ids = ids_[object->id()];
    if (auto v = object->vec3(P::kPosition)) user.position = *v;
    if (auto b = object->aabb(P::kBounds)) user.bounds = *b;
    if (auto id = object->idParam(P::kSdf)) ids.sdf = *id;
    if (auto id = object->idParam(P::kVelocityField)) ids.velocity = *id;
  }
  for (const auto chunk : message) {
    const auto resource = chunk.asResource();
    if (!resource) continue;
    for (auto& [userId, ids] : ids_) {
      const bool isSdf = resource->id() == ids.sdf;
      const bool isVelocity = resource->id() == ids.velocity;
      if (!isSdf && !isVelocity) continue;
      const std::string what =
          "user " + std::to_string(userId) + ": resource " + std::to_string(resource->id());
      const auto field = resource->field();
      if (!field || field->components() != (isSdf ? 1u : 3u)) {
        fail(what + (isSdf ? " (sdf) is not a scalar field" : " (velocity) is not a vector field"));
        continue;
      }
      UserSurface& user = users_[userId];
      if (isSdf) {
        user.dims = field->dims();
        user.origin = field->origin();
        user.spacing = field->spacing();
        user.sdf.resize(field->data().size());
        field->data().copyTo(std::span<float>(user.sdf));
      } else if (field->dims() != user.dims || field->spacing() != user.spacing ||
                 field->origin() != user.origin) {
        fail(what + " (velocity) lies on another grid than the user's distance field");
      } else {
        user.velocity.resize(field->data().size());
        field->data().copyTo(std::span<float>(user.velocity));
      }
    }
  }
  return result;
}

std::map<std::uint64_t, const UserSurface*> UserCopy::ready() const {
  std::map<std::uint64_t, const UserSurface*> users;
  for (const auto& [id, user] : users_)
    if (user.ready()) users.emplace(id, &user);
  return users;
}

}  // namespace vrflow::camera
