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
  auto& objects = module.addInput("objects");
  auto& forces = module.addOutput("forces");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s: %s\n", program, status.error().message.c_str());
    return 2;
  }
  modules::Params params(module, program);
  const double scale = params.number("scale");
  if (params.report()) return 2;
  SceneCopy scene;
  modules::Warnings warnings(program);
  while (module.wait()) {
    if (const Message& received = module.get(objects); received.valid()) {
      if (auto status = scene.apply(received.view()); !status)
        warnings.warn(status.error().message);
    }
    std::map<std::uint64_t, std::vector<double>> total;
    std::size_t nodes = 0;
    for (const auto& [id, net] : scene.nets()) {
      auto& f = total[id];
      f.assign(3 * net.nodeCount(), 0.0);
      addSpringForces(net, f);
      if (scale != 1.0) {
        for (auto& value : f) value *= scale;
      }
      nodes += net.nodeCount();
    }
    auto out = module.newMessage(128 + nodes * 40);
    modules::addNodeForces(out.builder(), total);
    if (!module.put(forces, std::move(out))) break;
  }
  return module.exitStatus();
}
