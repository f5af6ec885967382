#include "world.hpp"

#include "vrflow/message/builtin_types.hpp"

namespace vrflow::fluid {
namespace {

std::vector<double> toVector(const msg::PackedArray<double>& array) {
  std::vector<double> out(array.size());
  array.copyTo(out);
  return out;
}

// Closed boxes meet when they overlap or touch on every axis; unknown bounds meet everything.
bool meets(const std::optional<msg::Aabb>& bounds, const msg::Aabb* near) {
  if (near == nullptr || !bounds) return true;
  for (std::size_t a = 0; a < 3; ++a) {
    if (bounds->min[a] > near->max[a] || near->min[a] > bounds->max[a]) return false;
  }
  return true;
}

}  // namespace

Status World::apply(const msg::MessageView& message) {
  const auto rigidId = msg::rigidType().id();
  const auto netId = msg::massSpringType().id();
  for (const auto chunk : message) {
    if (auto resource = chunk.asResource()) {
      if (resource->kind() != msg::ResourceKind::Raw) continue;
      // Only resources named by a rigid object's shape are decoded; others are not ours.
      bool named = false;
      for (const auto& [id, rigid] : rigids_) named = named || rigid.shapeId == resource->id();
      auto shape = msg::decodeShape(resource->raw());
      if (!shape) {
        if (named) {
          return makeError("fluid: shape resource " + std::to_string(resource->id()) +
                           " cannot be decoded: " + shape.error().message);
        }
        continue;
      }
      shapes_[resource->id()] = std::move(*shape);
      continue;
    }
    auto object = chunk.asObject();
    if (!object) continue;
    if (object->typeId() == rigidId) {
      if (object->op() == msg::ObjectOp::Delete) {
        rigids_.erase(object->id());
        continue;
      }
      auto& rigid = rigids_[object->id()];
      rigid.body.id = object->id();
      if (auto v = object->vec3(msg::RigidParam::kPosition)) rigid.body.position = *v;
      if (auto q = object->quat(msg::RigidParam::kOrientation)) rigid.body.orientation = *q;
      if (auto v = object->vec3(msg::RigidParam::kLinearVelocity)) rigid.body.linearVelocity = *v;
      if (auto v = object->vec3(msg::RigidParam::kAngularVelocity)) rigid.body.angularVelocity = *v;
      if (auto m = object->scalar(msg::RigidParam::kMass)) rigid.body.mass = *m;
      if (auto s = object->idParam(msg::RigidParam::kShape)) rigid.shapeId = *s;
      if (auto b = object->aabb(msg::RigidParam::kBounds)) rigid.bounds = *b;
    } else if (object->typeId() == netId) {
      if (object->op() == msg::ObjectOp::Delete) {
        nets_.erase(object->id());
        continue;
      }
      auto& net = nets_[object->id()];
      if (auto a = object->doubleArray(msg::MassSpringParam::kPositions))
        net.positions = toVector(*a);
      if (auto a = object->doubleArray(msg::MassSpringParam::kVelocities))
        net.velocities = toVector(*a);
      if (auto a = object->doubleArray(msg::MassSpringParam::kMasses)) net.masses = toVector(*a);
      if (auto b = object->aabb(msg::MassSpringParam::kBounds)) net.bounds = *b;
    }
  }
  return users_.apply(message);
}

std::vector<RigidBody> World::rigidBodies(const msg::Aabb* near) const {
  std::vector<RigidBody> out;
  for (const auto& [id, rigid] : rigids_) {
    if (!meets(rigid.bounds, near)) continue;
    const auto shape = shapes_.find(rigid.shapeId);
    if (shape == shapes_.end()) continue;
    out.push_back(rigid.body);
    out.back().shape = shape->second;
    // The rigid package sends kinematic bodies (infinite mass) with mass 0.
    out.back().kinematic = !(rigid.body.mass > 0.0);
  }
  return out;
}

std::vector<RigidBody> World::users(const msg::Aabb* near) const {
  std::vector<RigidBody> out;
  for (const auto& [id, user] : users_.ready()) {
    if (!meets(user->bounds, near)) continue;
    RigidBody body;
    body.id = id;
    body.position = user->position;
    body.kinematic = true;
    body.surface = user;
    out.push_back(body);
  }
  return out;
}

std::vector<PointMass> World::pointMasses(const msg::Aabb* near) const {
  std::vector<PointMass> out;
  if (nodeRadius_ <= 0.0) return out;
  for (const auto& [id, net] : nets_) {
    if (!meets(net.bounds, near)) continue;
    const std::size_t n = net.positions.size() / 3;
    for (std::size_t i = 0; i < n; ++i) {
      PointMass p;
      p.id = id;
      p.index = static_cast<std::uint32_t>(i);
      p.position = {net.positions[3 * i], net.positions[3 * i + 1], net.positions[3 * i + 2]};
      if (net.velocities.size() >= 3 * (i + 1)) {
        p.velocity = {net.velocities[3 * i], net.velocities[3 * i + 1], net.velocities[3 * i + 2]};
      }
      p.mass = i < net.masses.size() && net.masses[i] > 0.0 ? net.masses[i] : 0.01;
      p.radius = nodeRadius_;
      out.push_back(p);
    }
  }
  return out;
}

std::vector<std::string> World::uncoupled() const {
  std::vector<std::string> out;
  for (const auto& [id, rigid] : rigids_) {
    if (!shapes_.contains(rigid.shapeId)) {
      out.push_back("rigid " + std::to_string(id) + ": shape resource " +
                    std::to_string(rigid.shapeId) + " not received");
    }
  }
  return out;
}

}  // namespace vrflow::fluid
