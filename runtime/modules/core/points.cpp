// core/points: an animator of point masses (semi-implicit Euler). Sends every point's full
// state once (add), then only the parameters that change (position, velocity).
#include <cstdio>
#include <fstream>
#include <unordered_map>
#include <vector>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

namespace {

struct Point {
  uint64_t id;
  vrflow::msg::Vec3 position, velocity, force;
};

}  // namespace

int main() {
  using namespace vrflow;
  Module module;
  const auto ports = startAnimator(module, "vrflow-core-points");
  if (!ports) return 2;
  const auto count = module.params().getInt("count");
  const double mass = module.params().getFloat("mass");
  const double dt = module.params().getFloat("dt");
  const double spacing = module.params().getFloat("spacing");
  std::ofstream log;
  if (const auto path = module.params().getString("log"); !path.empty())
    log.open(path, std::ios::app);

  std::vector<Point> points;
  std::unordered_map<uint64_t, std::size_t> index;
  for (int64_t i = 0; i < count; ++i) {
    points.push_back(
        {module.newId(), {spacing * static_cast<double>(i), 0, 0}, {0, 0, 0}, {0, 0, 0}});
    index[points.back().id] = points.size() - 1;
  }
  const auto& type = msg::pointType();
  double time = 0.0;
  while (module.wait()) {
    for (auto& p : points) p.force = {0, 0, 0};
    const Message& received = module.get(ports->events);
    if (log.is_open()) {
      log << module.id() << " " << module.iteration() << " <- ";
      if (received.valid()) {
        const auto stamps = received->stamps();
        log << stamps.source << "@" << stamps.iteration << " chunks=" << received->chunkCount();
      }
      log << "\n";
      log.flush();
    }
    if (received.valid()) {
      for (const auto chunk : received.view()) {
        const auto event = chunk.asEvent();
        if (!event || !event->isForce()) continue;
        const auto it = index.find(event->id());
        const auto force = event->force();
        if (it == index.end() || !force) continue;
        for (int k = 0; k < 3; ++k) points[it->second].force[k] += force->force[k];
      }
    }
    if (module.iteration() > 0) {
      for (auto& p : points) {
        for (int k = 0; k < 3; ++k) {
          p.velocity[k] += dt * p.force[k] / mass;
          p.position[k] += dt * p.velocity[k];
        }
      }
      time += dt;
    }
    auto out = module.newMessage(128 + points.size() * 128);
    auto& builder = out.builder();
    builder.setSimTime(time);
    builder.setTimeStep(dt);
    for (const auto& p : points) {
      if (module.iteration() == 0) {
        builder.addObject(p.id, type, msg::ObjectOp::Add)
            .set(msg::PointParam::kPosition, p.position)
            .set(msg::PointParam::kVelocity, p.velocity)
            .set(msg::PointParam::kMass, mass);
      } else {
        builder.addObject(p.id, type, msg::ObjectOp::Update)
            .set(msg::PointParam::kPosition, p.position)
            .set(msg::PointParam::kVelocity, p.velocity);
      }
    }
    if (!module.put(ports->objects, std::move(out))) break;
  }
  return module.exitStatus();
}
