// input-testing/clicks: a scripted window, for the tests of the window backend. Iteration i
// sends one pointer event (kind 1100) at time i dt from a keyframe file: its ray's origin and
// direction, its buttons; the action is Press or Release when the buttons change, else Move.
#include <cstdio>

#include "vrflow/input/keyframes.hpp"
#include "vrflow/module/start.hpp"

int main() {
  using namespace vrflow;
  Module module;
  const OutputPort& events = module.addOutput("events");
  if (!initOrReport(module, "vrflow-input-testing-clicks")) return 2;
  auto track = input::KeyframeTrack::load(module.params().getString("keyframes"));
  if (!track) {
    std::fprintf(stderr, "vrflow-input-testing-clicks: %s\n", track.error().message.c_str());
    return 2;
  }
  const double dt = module.params().getFloat("dt");
  std::uint32_t held = 0;
  while (module.wait()) {
    const double time = static_cast<double>(module.iteration()) * dt;
    const auto sample = track->at(time);
    msg::PointerEvent event;
    event.action = sample.buttons == held          ? msg::PointerAction::Move
                   : (sample.buttons & ~held) != 0 ? msg::PointerAction::Press
                                                   : msg::PointerAction::Release;
    held = sample.buttons;
    event.buttons = sample.buttons;
    event.rayOrigin = sample.position;
    event.rayDirection = sample.direction;
    event.time = time;
    auto out = module.newMessage(256);
    out.builder().setSimTime(time);
    out.builder().setTimeStep(dt);
    msg::addPointerEvent(out.builder(), 1, event);
    if (!module.put(events, std::move(out))) break;
  }
  return module.exitStatus();
}
