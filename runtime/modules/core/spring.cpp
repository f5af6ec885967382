// core/spring: damped springs joining consecutive points (by id order); the first point is
// held to where it was first seen by an extra spring of the same stiffness.
#include <cmath>
#include <cstdio>
#include <fstream>

#include "interactor_common.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

int main() {
  using namespace vrflow;
  Module module;
  const auto ports = startInteractor(module, "vrflow-core-spring");
  if (!ports) return 2;
  const double k = module.params().getFloat("stiffness");
  const double c = module.params().getFloat("damping");
  const double rest = module.params().getFloat("rest");
  std::ofstream log;
  if (const auto path = module.params().getString("log"); !path.empty())
    log.open(path, std::ios::app);

  std::map<uint64_t, core::PointState> points;
  bool anchored = false;
  msg::Vec3 anchor{};
  while (module.wait()) {
    const Message& received = module.get(ports->objects);
    if (log.is_open()) {
      const auto stamps = received->stamps();
      log << module.id() << " " << module.iteration() << " <- " << stamps.source << "@"
          << stamps.iteration << " chunks=" << received->chunkCount() << "\n";
      log.flush();
    }
    core::applyObjectChunks(received, points);
    std::map<uint64_t, msg::Vec3> total;
    auto addSpring = [&](uint64_t a, const msg::Vec3& pa, const msg::Vec3& va, uint64_t b,
                         const msg::Vec3& pb, const msg::Vec3& vb, bool bIsAnchor) {
      msg::Vec3 d{pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
      const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      if (length < 1e-12) return;
      const double restLength = bIsAnchor ? 0.0 : rest;
      double relSpeed = 0;
      for (int i = 0; i < 3; ++i) relSpeed += (vb[i] - va[i]) * d[i] / length;
      const double magnitude = k * (length - restLength) + c * relSpeed;
      for (int i = 0; i < 3; ++i) {
        total[a][i] += magnitude * d[i] / length;
        if (!bIsAnchor) total[b][i] -= magnitude * d[i] / length;
      }
    };
    if (!points.empty()) {
      const auto first = points.begin();
      if (!anchored) {
        anchor = first->second.position;
        anchored = true;
      }
      addSpring(first->first, first->second.position, first->second.velocity, 0, anchor, {0, 0, 0},
                true);
      for (auto it = points.begin(), next = std::next(it); next != points.end(); ++it, ++next) {
        addSpring(it->first, it->second.position, it->second.velocity, next->first,
                  next->second.position, next->second.velocity, false);
      }
    }
    auto out = module.newMessage(64 + total.size() * 112);
    for (const auto& [id, f] : total) {
      out.builder().addForce(id,
                             msg::ForceEvent{f, {0, 0, 0}, points[id].position, module.timeStep()});
    }
    if (!module.put(ports->forces, std::move(out))) break;
  }
  return module.exitStatus();
}
