#pragma once

#include <map>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/message.hpp"

namespace vrflow::core {

/// The interactors' local copy of point objects, kept up to date from object chunks
/// (add / update of changed parameters / delete), ordered by id for determinism.
struct PointState {
  msg::Vec3 position{};
  msg::Vec3 velocity{};
  double mass = 1.0;
};

inline void applyObjectChunks(const Message& message, std::map<uint64_t, PointState>& points) {
  if (!message.valid()) return;
  for (const auto chunk : message.view()) {
    const auto object = chunk.asObject();
    if (!object || object->typeId() != msg::pointType().id()) continue;
    if (object->op() == msg::ObjectOp::Delete) {
      points.erase(object->id());
      continue;
    }
    auto& p = points[object->id()];
    if (auto v = object->vec3(msg::PointParam::kPosition)) p.position = *v;
    if (auto v = object->vec3(msg::PointParam::kVelocity)) p.velocity = *v;
    if (auto v = object->scalar(msg::PointParam::kMass)) p.mass = *v;
  }
}

}  // namespace vrflow::core
