#include "vrflow/rigid/messages.hpp"

#include <cmath>
#include <string>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/chunk_views.hpp"

namespace vrflow::rigid {

using P = msg::RigidParam;

void writeAdd(msg::MessageBuilder& builder, const Body& body, std::uint64_t shapeId) {
  const auto bytes = msg::encodeShape(body.shape);
  builder.addRawResource(shapeId, false, bytes);
  auto object = builder.addObject(body.id, msg::rigidType(), msg::ObjectOp::Add);
  object.set(P::kPosition, body.position)
      .set(P::kOrientation, body.orientation)
      .set(P::kLinearVelocity, body.linearVelocity)
      .set(P::kAngularVelocity, body.angularVelocity)
      .set(P::kMass, body.kinematic ? 0.0 : body.mass)
      .set(P::kInertia, body.kinematic ? Mat3{} : body.inertia)
      .set(P::kBounds, msg::worldBounds(body.shape, body.position, body.orientation))
      .set(P::kShape, shapeId);
  // Materials travel only when the body has its own, so scenes without them send what they sent.
  if (body.friction >= 0) object.set(P::kFriction, body.friction);
  if (body.restitution >= 0) object.set(P::kRestitution, body.restitution);
}

void writeUpdate(msg::MessageBuilder& builder, const Body& body, const Change& change) {
  auto object = builder.addObject(body.id, msg::rigidType(), msg::ObjectOp::Update);
  if (change.pose) {
    object.set(P::kPosition, body.position)
        .set(P::kOrientation, body.orientation)
        .set(P::kBounds, msg::worldBounds(body.shape, body.position, body.orientation));
  }
  if (change.velocity)
    object.set(P::kLinearVelocity, body.linearVelocity)
        .set(P::kAngularVelocity, body.angularVelocity);
}

Status RigidObjectCopy::apply(const msg::MessageView& message,
                              std::vector<std::uint64_t>* deleted) {
  for (const auto chunk : message) {
    if (const auto resource = chunk.asResource()) {
      if (resource->kind() != msg::ResourceKind::Raw) continue;
      // Only resources a rigid object names (or will name in this message) are shapes; others
      // may be anything, so a resource that does not decode is an error only when referenced.
      auto shape = msg::decodeShape(resource->raw());
      if (shape) {
        shapes_[resource->id()] = std::move(shape.value());
        for (auto& [id, entry] : entries_)
          if (entry.shapeId == resource->id()) {
            entry.body.shape = shapes_[resource->id()];
            entry.hasShape = entry.shapeChanged = true;
          }
      }
      continue;
    }
    const auto object = chunk.asObject();
    if (!object || object->typeId() != msg::rigidType().id()) continue;
    if (object->op() == msg::ObjectOp::Delete) {
      if (entries_.erase(object->id()) > 0 && deleted) deleted->push_back(object->id());
      continue;
    }
    const bool isNew = !entries_.contains(object->id());
    Entry& e = entries_[object->id()];
    e.body.id = object->id();
    e.stateChanged = true;
    if (isNew) e.shapeChanged = true;
    if (auto v = object->vec3(P::kPosition)) e.body.position = *v;
    if (auto v = object->quat(P::kOrientation)) e.body.orientation = *v;
    if (auto v = object->vec3(P::kLinearVelocity)) e.body.linearVelocity = *v;
    if (auto v = object->vec3(P::kAngularVelocity)) e.body.angularVelocity = *v;
    if (auto v = object->scalar(P::kMass)) {
      e.body.kinematic = !(*v > 0);
      e.body.mass = e.body.kinematic ? kInfiniteMass : *v;
    }
    if (auto v = object->mat3(P::kInertia); v && !e.body.kinematic) e.body.inertia = *v;
    if (auto v = object->scalar(P::kFriction)) e.body.friction = *v;
    if (auto v = object->scalar(P::kRestitution)) e.body.restitution = *v;
    if (auto v = object->idParam(P::kShape); v && *v != e.shapeId) {
      e.shapeId = *v;
      const auto s = shapes_.find(*v);
      e.hasShape = s != shapes_.end();
      if (e.hasShape) e.body.shape = s->second;
      e.shapeChanged = true;
    }
  }
  for (const auto& [id, entry] : entries_)
    if (!entry.hasShape && entry.shapeId != 0 && !shapes_.contains(entry.shapeId))
      return makeError("rigid object " + std::to_string(id) + " names shape resource " +
                       std::to_string(entry.shapeId) +
                       ", which did not arrive or does not decode as a shape");
  return {};
}

}  // namespace vrflow::rigid
