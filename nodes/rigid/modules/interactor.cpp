// rigid/interactor: keeps a copy of the rigid objects it receives, finds their contacts with
// Bullet and answers with the contact impulses of our sequential impulse solver, as force events
// over the step (the animator applies them). Captured users (type `user`) are solids of infinite
// mass the bodies collide with through their distance field and surface velocity.
#include <cstdio>

#include "vrflow/camera/capture_stamps.hpp"
#include "vrflow/camera/user_copy.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"
#include "vrflow/rigid/contact_solver.hpp"
#include "vrflow/rigid/messages.hpp"

int main() {
  using namespace vrflow;
  Module module;
  const auto ports = startInteractor(module, "vrflow-rigid-interactor");
  if (!ports) return 2;
  rigid::ContactParams params;
  params.gravity = module.params().getVec3("gravity");
  params.restitution = module.params().getFloat("restitution");
  params.friction = module.params().getFloat("friction");
  params.iterations = static_cast<int>(module.params().getInt("iterations"));
  params.baumgarte = module.params().getFloat("baumgarte");
  params.slop = module.params().getFloat("slop");
  params.restitutionThreshold = module.params().getFloat("restitution-threshold");
  const double fallbackDt = module.params().getFloat("dt");
  rigid::RigidContactSolver solver(params);
  rigid::RigidObjectCopy copy;
  camera::UserCopy users;
  while (module.wait()) {
    const Message& received = module.get(ports->objects);
    std::vector<std::uint64_t> deleted;
    if (received.valid()) {
      if (auto status = copy.apply(received.view(), &deleted); !status) {
        std::fprintf(stderr, "vrflow-rigid-interactor: %s\n", status.error().message.c_str());
        return 1;
      }
      if (auto status = users.apply(received.view()); !status) {
        std::fprintf(stderr, "vrflow-rigid-interactor: %s\n", status.error().message.c_str());
        return 1;
      }
    }
    for (auto id : deleted) solver.removeBody(id);
    // Only the bodies this message added or updated: the others' poses and velocities are
    // already the solver's (the animator sends a body only when it changed; a settled scene
    // sends almost none).
    for (auto& [id, entry] : copy.entries()) {
      if (!entry.hasShape) continue;
      if (entry.shapeChanged || !solver.contains(id)) {
        if (auto status = solver.setBody(entry.body); !status) {
          std::fprintf(stderr, "vrflow-rigid-interactor: %s\n", status.error().message.c_str());
          return 1;
        }
        entry.shapeChanged = false;
      } else if (entry.stateChanged) {
        const auto& b = entry.body;
        solver.setState(id, b.position, b.orientation, b.linearVelocity, b.angularVelocity);
      }
      entry.stateChanged = false;
    }
    const double dt = module.timeStep() > 0 ? module.timeStep() : fallbackDt;
    solver.setUsers(users.ready());
    const auto impulses = solver.solve(dt);
    auto out = module.newMessage(64 + impulses.size() * 112);
    for (const auto& [id, event] : impulses) out.builder().addForce(id, event);
    // Which camera frame the user solved against came from (nodes/camera, latency in frames).
    if (const auto frame = users.captureIteration())
      out.builder().addInt64Stamp(camera::kUsedCaptureIterationStamp, *frame);
    if (!module.put(ports->forces, std::move(out))) break;
  }
  return module.exitStatus();
}
