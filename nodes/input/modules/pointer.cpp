// input/pointer: a kinematic rigid sphere at the device's tip, an animator without event input
// (the paper's section 3.7): the rigid interactor collides it with the bodies, so it pushes them.
#include "vrflow/input/module_device.hpp"
#include "vrflow/module/start.hpp"
#include "vrflow/rigid/messages.hpp"

int main() {
  using namespace vrflow;
  const std::string program = "vrflow-input-pointer";
  Module module;
  auto started = input::startDeviceModule(module, program);
  if (!started) return 2;
  const double dt = module.params().getFloat("dt");
  const double radius = module.params().getFloat("radius");
  rigid::Body body = rigid::makeKinematic(module.newId(), msg::Shape::sphere(radius), {0, 0, 0});
  const std::uint64_t shapeId = module.newId();
  while (module.wait()) {
    const double time = static_cast<double>(module.iteration()) * dt;
    const auto sample =
        input::nextSample(module, &started->events, *started->device, program, time);
    if (!sample) return 1;
    body.position = sample->position;
    body.orientation = sample->orientation;
    body.linearVelocity = sample->velocity;
    auto out = module.newMessage(512);
    out.builder().setSimTime(time);
    out.builder().setTimeStep(dt);
    if (module.iteration() == 0)
      rigid::writeAdd(out.builder(), body, shapeId);
    else
      rigid::writeUpdate(out.builder(), body, {body.id, true, true});
    if (!module.put(started->objects, std::move(out))) break;
  }
  return module.exitStatus();
}
