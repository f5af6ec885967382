// core/gravity: a uniform force field, the weight m g of every point.
#include <cstdio>

#include "interactor_common.hpp"
#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& objects = module.addInput("objects");
  auto& forces = module.addOutput("forces");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "vrflow-core-gravity: %s\n", status.error().message.c_str());
    return 2;
  }
  const msg::Vec3 g = module.params().getVec3("g");
  std::map<uint64_t, core::PointState> points;
  while (module.wait()) {
    core::applyObjectChunks(module.get(objects), points);
    auto out = module.newMessage(64 + points.size() * 112);
    for (const auto& [id, p] : points) {
      const msg::Vec3 weight{p.mass * g[0], p.mass * g[1], p.mass * g[2]};
      out.builder().addForce(id, msg::ForceEvent{weight, {0, 0, 0}, p.position, module.timeStep()});
    }
    if (!module.put(forces, std::move(out))) break;
  }
  return module.exitStatus();
}
