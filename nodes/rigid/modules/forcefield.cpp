// rigid/forcefield: gravity, uniform forces, point attractors and drag on the objects it
// receives, by type (rigid bodies, point masses).
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"
#include "vrflow/rigid/force_field.hpp"
#include "vrflow/rigid/messages.hpp"

int main() {
  using namespace vrflow;
  Module module;
  const auto ports = startInteractor(module, "vrflow-rigid-forcefield");
  if (!ports) return 2;
  auto field = rigid::ForceField::parse(module.params().getString("field"));
  if (!field) {
    std::fprintf(stderr, "vrflow-rigid-forcefield: parameter 'field': %s\n",
                 field.error().message.c_str());
    return 2;
  }
  bool rigidBodies = false, points = false;
  std::istringstream types(module.params().getString("types"));
  for (std::string type; types >> type;) {
    if (type == "rigid")
      rigidBodies = true;
    else if (type == "point")
      points = true;
    else {
      std::fprintf(stderr,
                   "vrflow-rigid-forcefield: parameter 'types': unknown type '%s' (rigid, point)\n",
                   type.c_str());
      return 2;
    }
  }
  const double fallbackDt = module.params().getFloat("dt");
  std::map<std::uint64_t, rigid::FieldTarget> targets;  // by id, for a fixed order
  while (module.wait()) {
    const Message& received = module.get(ports->objects);
    if (received.valid()) {
      for (const auto chunk : received.view()) {
        const auto object = chunk.asObject();
        if (!object) continue;
        const bool isRigid = object->typeId() == msg::rigidType().id();
        const bool isPoint = object->typeId() == msg::pointType().id();
        if (!((isRigid && rigidBodies) || (isPoint && points))) continue;
        if (object->op() == msg::ObjectOp::Delete) {
          targets.erase(object->id());
          continue;
        }
        auto& t = targets[object->id()];
        if (isRigid) {
          using P = msg::RigidParam;
          if (auto v = object->vec3(P::kPosition)) t.position = *v;
          if (auto v = object->vec3(P::kLinearVelocity)) t.linearVelocity = *v;
          if (auto v = object->vec3(P::kAngularVelocity)) t.angularVelocity = *v;
          if (auto v = object->scalar(P::kMass))
            t.mass = *v > 0 ? *v : rigid::kInfiniteMass;  // 0: kinematic
        } else {
          using P = msg::PointParam;
          if (auto v = object->vec3(P::kPosition)) t.position = *v;
          if (auto v = object->vec3(P::kVelocity)) t.linearVelocity = *v;
          if (auto v = object->scalar(P::kMass)) t.mass = *v;
        }
      }
    }
    const double dt = module.timeStep() > 0 ? module.timeStep() : fallbackDt;
    auto out = module.newMessage(64 + targets.size() * 112);
    for (const auto& [id, target] : targets) {
      if (!std::isfinite(target.mass)) continue;
      out.builder().addForce(id, field->forceOn(target, dt));
    }
    if (!module.put(ports->forces, std::move(out))) break;
  }
  return module.exitStatus();
}
