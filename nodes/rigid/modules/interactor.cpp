// rigid/interactor: keeps a copy of the rigid objects it receives, finds their contacts with
// Bullet and answers with the contact impulses of our sequential impulse solver, as force events
// over the step (the animator applies them).
#include <cstdio>
#include <sstream>

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
  std::istringstream g(module.param("gravity", "0 -9.81 0"));
  if (!(g >> params.gravity[0] >> params.gravity[1] >> params.gravity[2])) {
    std::fprintf(stderr, "vrflow-rigid-interactor: gravity must be three numbers\n");
    return 2;
  }
  params.restitution = module.paramDouble("restitution", params.restitution);
  params.friction = module.paramDouble("friction", params.friction);
  params.iterations = static_cast<int>(module.paramInt("iterations", params.iterations));
  params.baumgarte = module.paramDouble("baumgarte", params.baumgarte);
  params.slop = module.paramDouble("slop", params.slop);
  params.restitutionThreshold =
      module.paramDouble("restitution-threshold", params.restitutionThreshold);
  const double fallbackDt = module.paramDouble("dt", 0.01);
  rigid::RigidContactSolver solver(params);
  rigid::RigidObjectCopy copy;
  while (module.wait()) {
    const Message& received = module.get(ports->objects);
    std::vector<std::uint64_t> deleted;
    if (received.valid()) {
      if (auto status = copy.apply(received.view(), &deleted); !status) {
        std::fprintf(stderr, "vrflow-rigid-interactor: %s\n", status.error().message.c_str());
        return 1;
      }
    }
    for (auto id : deleted) solver.removeBody(id);
    for (auto& [id, entry] : copy.entries()) {
      if (!entry.hasShape) continue;
      if (entry.shapeChanged || !solver.contains(id)) {
        if (auto status = solver.setBody(entry.body); !status) {
          std::fprintf(stderr, "vrflow-rigid-interactor: %s\n", status.error().message.c_str());
          return 1;
        }
        entry.shapeChanged = false;
      } else {
        const auto& b = entry.body;
        solver.setState(id, b.position, b.orientation, b.linearVelocity, b.angularVelocity);
      }
    }
    const double dt = module.timeStep() > 0 ? module.timeStep() : fallbackDt;
    const auto impulses = solver.solve(dt);
    auto out = module.newMessage(64 + impulses.size() * 112);
    for (const auto& [id, event] : impulses) out.builder().addForce(id, event);
    if (!module.put(ports->forces, std::move(out))) break;
  }
  return module.exitStatus();
}
