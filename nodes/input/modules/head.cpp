// input/head: a tracked head position, a `point` object per iteration, for the display wall's
// head-coupled frustum.
#include "vrflow/input/module_device.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/start.hpp"

int main() {
  using namespace vrflow;
  const std::string program = "vrflow-input-head";
  Module module;
  auto started = input::startDeviceModule(module, program);
  if (!started) return 2;
  const double dt = module.params().getFloat("dt");
  const std::uint64_t id = module.newId();
  using P = msg::PointParam;
  while (module.wait()) {
    const double time = static_cast<double>(module.iteration()) * dt;
    const auto sample =
        input::nextSample(module, &started->events, *started->device, program, time);
    if (!sample) return 1;
    auto out = module.newMessage(256);
    out.builder().setSimTime(time);
    out.builder().setTimeStep(dt);
    out.builder()
        .addObject(id, msg::pointType(),
                   module.iteration() == 0 ? msg::ObjectOp::Add : msg::ObjectOp::Update)
        .set(P::kPosition, sample->position)
        .set(P::kVelocity, sample->velocity)
        .set(P::kMass, 0.0);
    if (!module.put(started->objects, std::move(out))) break;
  }
  return module.exitStatus();
}
