// core/gravity: a uniform force field, the weight m g of every point.
#include <cstdio>

#include "interactor_common.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

int main() {
  using namespace vrflow;
  Module module;
  const auto ports = startInteractor(module, "vrflow-core-gravity");
  if (!ports) return 2;
  const msg::Vec3 g = module.params().getVec3("g");
  std::map<uint64_t, core::PointState> points;
  while (module.wait()) {
    core::applyObjectChunks(module.get(ports->objects), points);
    auto out = module.newMessage(64 + points.size() * 112);
    for (const auto& [id, p] : points) {
      const msg::Vec3 weight{p.mass * g[0], p.mass * g[1], p.mass * g[2]};
      out.builder().addForce(id, msg::ForceEvent{weight, {0, 0, 0}, p.position, module.timeStep()});
    }
    if (!module.put(ports->forces, std::move(out))) break;
  }
  return module.exitStatus();
}
