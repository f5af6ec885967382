// massspring/rigid: the rigid / mass-spring interactor. Nodes of every net against every rigid
// shape (signed distance in the body frame); node forces to the nets, and to each touched rigid
// one ForceEvent with the opposite total force at its centre of mass and the torque about it.
#include <cstdio>

#include "common.hpp"
#include "vrflow/massspring/contact.hpp"
#include "vrflow/massspring/objects.hpp"

int main() {
  using namespace vrflow;
  using namespace vrflow::massspring;
  const char* program = "vrflow-massspring-rigid";
  Module module;
  const auto ports = startInteractor(module, program);
  if (!ports) return 2;
  modules::Params params(module, program);
  ContactParams contact;
  contact.thickness = params.number("thickness");
  contact.beta = params.number("beta");
  const double fallbackDt = params.number("dt");
  contact.springMassWeight = params.number("spring-mass-weight");
  if (params.report()) return 2;
  ContactMemory memory;
  return modules::runInteractor(module, *ports, program, [&](const SceneCopy& scene) {
    contact.dt = module.timeStep() > 0 ? module.timeStep() : fallbackDt;
    const auto result = rigidContacts(scene.nets(), scene.rigids(), contact, &memory);
    auto out =
        modules::nodeForcesMessage(module, result.nodeForces, result.rigidForces.size() * 128);
    for (const auto& [id, force] : result.rigidForces) out.builder().addForce(id, force);
    return out;
  });
}
