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
  auto& objects = module.addInput("objects");
  auto& forces = module.addOutput("forces");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s: %s\n", program, status.error().message.c_str());
    return 2;
  }
  modules::Params params(module, program);
  ContactParams contact;
  contact.thickness = params.number("thickness");
  contact.beta = params.number("beta");
  const double fallbackDt = params.number("dt");
  contact.springMassWeight = params.number("spring-mass-weight");
  if (params.report()) return 2;
  SceneCopy scene;
  ContactMemory memory;
  modules::Warnings warnings(program);
  while (module.wait()) {
    if (const Message& received = module.get(objects); received.valid()) {
      if (auto status = scene.apply(received.view()); !status)
        warnings.warn(status.error().message);
    }
    contact.dt = module.timeStep() > 0 ? module.timeStep() : fallbackDt;
    const auto result = netCollisions(scene.nets(), contact, &memory);
    std::size_t nodes = 0;
    for (const auto& [id, f] : result.nodeForces) nodes += f.size() / 3;
    auto out = module.newMessage(128 + nodes * 40);
    modules::addNodeForces(out.builder(), result.nodeForces);
    if (!module.put(forces, std::move(out))) break;
  }
  return module.exitStatus();
}
