// input/head: a tracked head position, a `point` object per iteration, for the display wall's
// head-coupled frustum.
#include <cstdio>

#include "vrflow/input/module_device.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/start.hpp"

int main() {
  using namespace vrflow;
  const std::string program = "vrflow-input-head";
  Module module;
  const InputPort& events = module.addInput("device");
  const OutputPort& objects = module.addOutput("objects");
  if (!initOrReport(module, program)) return 2;
  auto device = input::openModuleDevice(module, program);
  if (!device) return 2;
  const double dt = module.params().getFloat("dt");
  const std::uint64_t id = module.newId();
  using P = msg::PointParam;
  while (module.wait()) {
    input::feedPointerEvents(*device, module.get(events));
    const double time = static_cast<double>(module.iteration()) * dt;
    auto sample = device->sample(time);
    if (!sample) {
      std::fprintf(stderr, "%s: %s\n", program.c_str(), sample.error().message.c_str());
      return 1;
    }
    auto out = module.newMessage(256);
    out.builder().setSimTime(time);
    out.builder().setTimeStep(dt);
    out.builder()
        .addObject(id, msg::pointType(),
                   module.iteration() == 0 ? msg::ObjectOp::Add : msg::ObjectOp::Update)
        .set(P::kPosition, sample->position)
        .set(P::kVelocity, sample->velocity)
        .set(P::kMass, 0.0);
    if (!module.put(objects, std::move(out))) break;
  }
  return module.exitStatus();
}
