#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "vrflow/message/builder.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/byte_sink.hpp"
#include "vrflow/message/reader.hpp"
#include "vrflow/message/shape.hpp"
#include "vrflow/viewer/scene_cache.hpp"

namespace vrflow::viewer::testing {

/// Builds one message with `fill` and applies it to `scene`; false if the message is malformed.
inline bool feed(SceneCache& scene, const std::function<void(msg::MessageBuilder&)>& fill) {
  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  fill(builder);
  const std::size_t size = builder.finish();
  auto view = msg::MessageView::parse(std::span(sink.buffer()).first(size));
  if (!view) return false;
  scene.apply(*view);
  return true;
}

/// Adds a static shape resource.
inline void addShape(msg::MessageBuilder& builder, std::uint64_t id, const msg::Shape& shape) {
  const auto bytes = msg::encodeShape(shape);
  builder.addRawResource(id, false, bytes);
}

/// Adds a rigid object with every parameter the viewer reads.
inline void addRigid(msg::MessageBuilder& builder, std::uint64_t id, const msg::Vec3& position,
                     std::uint64_t shapeId, const msg::Quat& orientation = {0, 0, 0, 1}) {
  builder.addObject(id, msg::rigidType(), msg::ObjectOp::Add)
      .set(msg::RigidParam::kPosition, position)
      .set(msg::RigidParam::kOrientation, orientation)
      .set(msg::RigidParam::kMass, 1.0)
      .set(msg::RigidParam::kShape, shapeId);
}

/// Adds a net: masses xyz and triangles over them.
inline void addNet(msg::MessageBuilder& builder, std::uint64_t id, const std::vector<double>& xyz,
                   const std::vector<std::uint32_t>& triangles) {
  builder.addObject(id, msg::massSpringType(), msg::ObjectOp::Add)
      .set(msg::MassSpringParam::kPositions, std::span<const double>(xyz))
      .set(msg::MassSpringParam::kSurface, std::as_bytes(std::span(triangles)));
}

}  // namespace vrflow::viewer::testing
