// massspring/collision: nodes of each net against the surface triangles of the other nets
// (vrflow/massspring/contact.hpp); repulsive node forces to both nets.
#include <cstdio>

#include "common.hpp"
#include "vrflow/massspring/contact.hpp"
#include "vrflow/massspring/objects.hpp"

int main() {
  using namespace vrflow;
  using namespace vrflow::massspring;
  const char* program = "vrflow-massspring-collision";
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
    return modules::nodeForcesMessage(module,
                                      netCollisions(scene.nets(), contact, &memory).nodeForces);
  });
}
