#include "vrflow/massspring/objects.hpp"

#include <cmath>

#include "vrflow/message/builtin_types.hpp"

namespace vrflow::massspring {
namespace {

// Applies an update that carries only positions, velocities and bounds, each of the net's size,
// in place: no copy of the net and nothing else to check, since the message's parse already
// rejected NaN and infinite numbers in a known type's parameters (docs/message-layout.md). This
// is what a moving net sends every iteration. False, with `net` unchanged, for any other update.
bool updateMotionInPlace(const msg::ObjectView& object, Net& net) {
  using P = msg::MassSpringParam;
  if (object.type() == nullptr) return false;  // not checked against the type: validate fully
  for (const auto index : {P::kMasses, P::kPinned, P::kSprings, P::kSurface})
    if (object.has(index)) return false;
  const auto positions = object.doubleArray(P::kPositions);
  const auto velocities = object.doubleArray(P::kVelocities);
  if ((positions && positions->size() != net.positions.size()) ||
      (velocities && velocities->size() != net.velocities.size()))
    return false;
  if (positions) positions->copyTo(std::span<double>(net.positions));
  if (velocities) velocities->copyTo(std::span<double>(net.velocities));
  return true;
}

}  // namespace

void writeNet(msg::MessageBuilder& builder, std::uint64_t id, const Net& net, bool full) {
  using P = msg::MassSpringParam;
  auto writer = builder.addObject(id, msg::massSpringType(),
                                  full ? msg::ObjectOp::Add : msg::ObjectOp::Update);
  writer.set(P::kPositions, std::span<const double>(net.positions))
      .set(P::kVelocities, std::span<const double>(net.velocities))
      .set(P::kBounds, bounds(net));
  if (!full) return;
  const auto springs = encodeSprings(net.springs);
  const auto surface = encodeIndices(net.surface);
  writer.set(P::kMasses, std::span<const double>(net.masses))
      .set(P::kPinned, std::as_bytes(std::span<const std::uint8_t>(net.pinned)))
      .set(P::kSprings, std::span<const std::byte>(springs))
      .set(P::kSurface, std::span<const std::byte>(surface));
}

Status SceneCopy::apply(const msg::MessageView& message) {
  const auto netType = msg::massSpringType().id();
  const auto rigidType = msg::rigidType().id();
  Status result;
  auto fail = [&](std::string text) {
    if (result) result = makeError(std::move(text));
  };
  for (const auto chunk : message) {
    if (auto resource = chunk.asResource()) {
      // Only Raw resources that a known rigid names as its shape are decoded (others are ignored).
      if (resource->kind() != msg::ResourceKind::Raw) continue;
      bool named = false;
      for (const auto& [id, entry] : rigids_) named = named || entry.shapeId == resource->id();
      if (!named) {
        // A shape may arrive before the rigid that names it: keep it if it decodes as a shape.
        if (auto shape = msg::decodeShape(resource->raw()))
          shapes_[resource->id()] = std::move(*shape);
        continue;
      }
      auto shape = msg::decodeShape(resource->raw());
      if (!shape) {
        fail("shape resource " + std::to_string(resource->id()) + ": " + shape.error().message);
        continue;
      }
      shapes_[resource->id()] = std::move(*shape);
      continue;
    }
    const auto object = chunk.asObject();
    if (!object) continue;
    if (object->typeId() == netType) {
      if (object->op() == msg::ObjectOp::Delete) {
        nets_.erase(object->id());
        continue;
      }
      if (object->op() == msg::ObjectOp::Update) {
        const auto found = nets_.find(object->id());
        if (found != nets_.end() && updateMotionInPlace(*object, found->second)) continue;
      }
      using P = msg::MassSpringParam;
      Net net = object->op() == msg::ObjectOp::Add ? Net{} : nets_[object->id()];
      if (auto a = object->doubleArray(P::kPositions)) {
        net.positions.resize(a->size());
        a->copyTo(std::span<double>(net.positions));
      }
      if (auto a = object->doubleArray(P::kVelocities)) {
        net.velocities.resize(a->size());
        a->copyTo(std::span<double>(net.velocities));
      }
      if (auto a = object->doubleArray(P::kMasses)) {
        net.masses.resize(a->size());
        a->copyTo(std::span<double>(net.masses));
      }
      if (auto b = object->bytes(P::kPinned)) {
        net.pinned.resize(b->size());
        for (std::size_t i = 0; i < b->size(); ++i)
          net.pinned[i] = static_cast<std::uint8_t>((*b)[i]);
      }
      if (auto b = object->bytes(P::kSprings)) {
        auto springs = decodeSprings(*b);
        if (!springs) {
          fail("net " + std::to_string(object->id()) + ": " + springs.error().message);
          continue;
        }
        net.springs = std::move(*springs);
      }
      if (auto b = object->bytes(P::kSurface)) {
        auto surface = decodeIndices(*b);
        if (!surface) {
          fail("net " + std::to_string(object->id()) + ": " + surface.error().message);
          continue;
        }
        net.surface = std::move(*surface);
      }
      if (auto status = validateNet(net); !status) {
        fail("net " + std::to_string(object->id()) + ": " + status.error().message);
        continue;
      }
      nets_[object->id()] = std::move(net);
    } else if (object->typeId() == rigidType) {
      if (object->op() == msg::ObjectOp::Delete) {
        rigids_.erase(object->id());
        continue;
      }
      using P = msg::RigidParam;
      auto& entry = rigids_[object->id()];
      if (auto v = object->vec3(P::kPosition)) entry.body.position = *v;
      if (auto v = object->quat(P::kOrientation)) entry.body.orientation = *v;
      if (auto v = object->vec3(P::kLinearVelocity)) entry.body.linearVelocity = *v;
      if (auto v = object->vec3(P::kAngularVelocity)) entry.body.angularVelocity = *v;
      if (auto v = object->scalar(P::kMass)) entry.body.mass = *v;
      if (auto v = object->idParam(P::kShape)) entry.shapeId = *v;
    }
  }
  if (auto status = users_.apply(message); !status) fail(status.error().message);
  return result;
}

std::map<std::uint64_t, RigidBody> SceneCopy::rigids() const {
  std::map<std::uint64_t, RigidBody> out;
  for (const auto& [id, entry] : rigids_) {
    const auto shape = shapes_.find(entry.shapeId);
    if (shape == shapes_.end()) continue;
    RigidBody body = entry.body;
    body.shape = shape->second;
    out.emplace(id, std::move(body));
  }
  return out;
}

}  // namespace vrflow::massspring
