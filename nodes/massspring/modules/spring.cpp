// massspring/spring: the spring interactor. For every net it receives it evaluates the net's own
// springs (constant stiffness, damping along the spring) on the received state and sends them as
// "massspring node forces" events, held by the animator over its sub-steps. Use it with an
// animator whose internal-springs is false (the paper's split); with internal springs on, the
// animator already evaluates the same spring code at every sub-step and this module must not be
// connected to it (the forces would count twice). The maximum-stretch constraint is always
// enforced by the animator, the only writer of positions.
#include <cstdio>

#include "common.hpp"
#include "vrflow/massspring/objects.hpp"
#include "vrflow/massspring/solver.hpp"

int main() {
  using namespace vrflow;
  using namespace vrflow::massspring;
  const char* program = "vrflow-massspring-spring";
  Module module;
  const auto ports = startInteractor(module, program);
  if (!ports) return 2;
  modules::Params params(module, program);
  const double scale = params.number("scale");
  if (params.report()) return 2;
  return modules::runInteractor(module, *ports, program, [&](const SceneCopy& scene) {
    std::map<std::uint64_t, std::vector<double>> total;
    for (const auto& [id, net] : scene.nets()) {
      auto& f = total[id];
      f.assign(3 * net.nodeCount(), 0.0);
      addSpringForces(net, f);
      if (scale != 1.0) {
        for (auto& value : f) value *= scale;
      }
    }
    return modules::nodeForcesMessage(module, total);
  });
}
