// fluidtest/box: a tiny rigid animator for the fluid's end-to-end tests: one cubic box,
// translation only (semi-implicit Euler from the force events it receives plus its own gravity),
// the plane y = 0 as a floor. Writes `iteration,y,vy` per iteration to `trajectory`. With
// `broken-at` = k > 0 it sends, from iteration k on, an orientation quaternion of zero, as a
// broken animator would: a well-formed message (finite numbers) with a body that the fluid's
// solver must refuse, for the fluid's failure tests.
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/shape.hpp"
#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& events = module.addInput("events");
  auto& objects = module.addOutput("objects");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "vrflow-fluidtest-box: %s\n", status.error().message.c_str());
    return 2;
  }
  const double half = module.params().getFloat("half");
  const double density = module.params().getFloat("density");
  const double dt = module.params().getFloat("dt");
  const auto brokenAt = static_cast<std::uint64_t>(module.params().getInt("broken-at"));
  msg::Vec3 position = module.params().getVec3("start");
  std::ofstream trajectory(module.params().getString("trajectory"), std::ios::trunc);
  const double mass = density * 8 * half * half * half;
  const auto shape = msg::Shape::box({half, half, half});
  const auto shapeBytes = msg::encodeShape(shape);
  const auto inertia = msg::massProperties(shape, mass).inertia;
  const std::uint64_t id = module.newId();
  const std::uint64_t shapeId = module.newId();
  msg::Vec3 velocity{};
  while (module.wait()) {
    msg::Vec3 force{};
    const Message& received = module.get(events);
    if (received.valid()) {
      for (const auto chunk : received.view()) {
        const auto event = chunk.asEvent();
        if (!event || event->id() != id) continue;
        if (const auto f = event->force()) {
          for (int a = 0; a < 3; ++a) force[a] += f->force[a];
        }
      }
    }
    if (module.iteration() > 0) {
      for (int a = 0; a < 3; ++a) {
        velocity[a] += (force[a] / mass + (a == 1 ? -9.81 : 0.0)) * dt;
        position[a] += velocity[a] * dt;
      }
      if (position[1] < half) {
        position[1] = half;
        if (velocity[1] < 0) velocity[1] = 0;
      }
    }
    trajectory << module.iteration() << ',' << position[1] << ',' << velocity[1] << '\n';
    auto out = module.newMessage(1024);
    auto& b = out.builder();
    b.setTimeStep(dt);
    b.setSimTime(static_cast<double>(module.iteration()) * dt);
    const msg::Aabb bounds{{position[0] - half, position[1] - half, position[2] - half},
                           {position[0] + half, position[1] + half, position[2] + half}};
    if (module.iteration() == 0) {
      b.addRawResource(shapeId, false, shapeBytes);
      b.addObject(id, msg::rigidType(), msg::ObjectOp::Add)
          .set(msg::RigidParam::kPosition, position)
          .set(msg::RigidParam::kOrientation, msg::Quat{0, 0, 0, 1})
          .set(msg::RigidParam::kLinearVelocity, velocity)
          .set(msg::RigidParam::kAngularVelocity, msg::Vec3{})
          .set(msg::RigidParam::kMass, mass)
          .set(msg::RigidParam::kInertia, inertia)
          .set(msg::RigidParam::kBounds, bounds)
          .set(msg::RigidParam::kShape, shapeId);
    } else {
      auto object = b.addObject(id, msg::rigidType(), msg::ObjectOp::Update);
      object.set(msg::RigidParam::kPosition, position)
          .set(msg::RigidParam::kLinearVelocity, velocity)
          .set(msg::RigidParam::kBounds, bounds);
      if (brokenAt > 0 && module.iteration() >= brokenAt) {
        object.set(msg::RigidParam::kOrientation, msg::Quat{0.0, 0.0, 0.0, 0.0});
      }
    }
    if (!module.put(objects, std::move(out))) break;
  }
  return module.exitStatus();
}
