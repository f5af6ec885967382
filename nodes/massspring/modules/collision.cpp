// massspring/collision: nodes of each net against the surface triangles of the other nets
// (vrflow/massspring/contact.hpp); repulsive node forces to both nets.
#include <cstdio>

#include "common.hpp"
#include "vrflow/massspring/contact.hpp"
#include "vrflow/massspring/objects.hpp"

int main() {
  using namespace vrflow;
  using namespace vrflow::massspring;
  return modules::runContactInteractor(
      "vrflow-massspring-collision", [](Module& module, const SceneCopy& scene,
                                        const ContactParams& contact, ContactMemory* memory) {
        return modules::nodeForcesMessage(module,
                                          netCollisions(scene.nets(), contact, memory).nodeForces);
      });
}
