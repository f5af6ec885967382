// input/haptic: a two-way animator with virtual coupling (model and passivity bound in
// vrflow/input/coupling.hpp). It owns a tool, a dynamic rigid sphere that takes part in the
// rigid interactor's contacts; each tick (its `dt`, 1 kHz by default) it joins the device's
// proxy to the tool by a spring-damper, applies the contact forces it receives on `events` to
// the tool, and renders the coupling's reaction back to the device as the feedback force.
// The physics runs slower: put a `decimate` filter on `objects` and a `repeat` filter on
// `events` (nodes/input/README.md). Every `objects` message is self-contained (the tool's shape
// resource and add chunk), so that a decimate filter in between loses nothing.
#include <time.h>

#include <cstdio>
#include <memory>

#include "vrflow/input/coupling.hpp"
#include "vrflow/input/module_device.hpp"
#include "vrflow/module/start.hpp"
#include "vrflow/rigid/messages.hpp"

int main() {
  using namespace vrflow;
  const std::string program = "vrflow-input-haptic";
  Module module;
  const InputPort& events = module.addInput("events");
  const OutputPort& objects = module.addOutput("objects");
  const OutputPort& feedback = module.addOutput("feedback");
  if (!initOrReport(module, program)) return 2;
  const auto& params = module.params();
  input::CouplingParams coupling;
  coupling.stiffness = params.getFloat("stiffness");
  coupling.damping = params.getFloat("damping");
  coupling.toolMass = params.getFloat("tool-mass");
  coupling.period = params.getFloat("dt");
  coupling.physicsPeriod = params.getFloat("physics-dt");
  coupling.gravity = params.getVec3("gravity");
  if (auto status = input::checkCoupling(coupling); !status) {
    std::fprintf(stderr, "%s: parameter 'stiffness' of module '%s': %s\n", program.c_str(),
                 module.id().c_str(), status.error().message.c_str());
    return 2;
  }
  auto device = input::openModuleDevice(module, program, true);
  if (!device) return 2;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> log(nullptr, std::fclose);
  if (const auto path = params.getString("log"); !path.empty()) {
    log.reset(std::fopen(path.c_str(), "w"));
    if (!log) {
      std::fprintf(stderr, "%s: parameter 'log' of module '%s': cannot write %s\n", program.c_str(),
                   module.id().c_str(), path.c_str());
      return 2;
    }
    std::fprintf(log.get(),
                 "time,device_x,device_y,device_z,tool_x,tool_y,tool_z,"
                 "contact_x,contact_y,contact_z,feedback_x,feedback_y,feedback_z\n");
  }
  const double dt = coupling.period;
  const auto first = input::nextSample(module, nullptr, *device, program, 0.0);
  if (!first) return 1;
  input::HapticTool tool(coupling, first->position);
  rigid::Body body =
      rigid::makeBody(module.newId(), msg::Shape::sphere(params.getFloat("tool-radius")),
                      coupling.toolMass, first->position);
  const std::uint64_t shapeId = module.newId();
  // Real time: tick i waits for its inputs no earlier than start + i dt on the monotonic clock
  // (a real device's servo rate); otherwise the loop runs as fast as its inputs allow.
  const bool realtime = params.getBool("realtime");
  timespec start{};
  clock_gettime(CLOCK_MONOTONIC, &start);
  for (std::uint64_t tick = 0;; ++tick) {
    if (realtime) {
      const double due = static_cast<double>(tick) * dt;
      timespec at = start;
      const auto whole = static_cast<time_t>(due);
      at.tv_sec += whole;
      at.tv_nsec += static_cast<long>((due - static_cast<double>(whole)) * 1e9);
      if (at.tv_nsec >= 1000000000L) {
        at.tv_nsec -= 1000000000L;
        ++at.tv_sec;
      }
      clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, nullptr);
    }
    if (!module.wait()) break;
    msg::Vec3 contact{};
    if (const Message& received = module.get(events); received.valid()) {
      for (const auto chunk : received.view()) {
        const auto event = chunk.asEvent();
        if (!event || !event->isForce() || event->id() != body.id) continue;
        if (const auto force = event->force())
          for (int k = 0; k < 3; ++k) contact[k] += force->force[k];
      }
    }
    const double time = static_cast<double>(module.iteration()) * dt;
    const auto sample = input::nextSample(module, nullptr, *device, program, time);
    if (!sample) return 1;
    const msg::Vec3 force = tool.step(*sample, contact);
    device->render(force, dt);
    body.position = tool.position();
    body.linearVelocity = tool.velocity();
    if (log) {
      const auto& d = sample->position;
      const auto& t = tool.position();
      std::fprintf(log.get(),
                   "%.9g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                   time + dt, d[0], d[1], d[2], t[0], t[1], t[2], contact[0], contact[1],
                   contact[2], force[0], force[1], force[2]);
    }
    auto out = module.newMessage(512);
    out.builder().setSimTime(time + dt);
    out.builder().setTimeStep(dt);
    rigid::writeAdd(out.builder(), body, shapeId);
    if (!module.put(objects, std::move(out))) break;
    if (feedback.connected()) {
      auto sent = module.newMessage(256);
      sent.builder().setSimTime(time + dt);
      sent.builder().setTimeStep(dt);
      sent.builder().addForce(body.id, {force, {}, sample->position, dt});
      if (!module.put(feedback, std::move(sent))) break;
    }
  }
  return module.exitStatus();
}
