// input/grab: an interactor that pulls the object the pointer picks (ray or point against the
// objects' bounds, when the grab button is pressed) towards the pointer with a spring-damper,
// as force events the rigid animator applies; releasing the button lets the object go.
#include <Eigen/Geometry>
#include <cstdio>
#include <optional>

#include "vrflow/input/module_device.hpp"
#include "vrflow/input/pick.hpp"
#include "vrflow/message/eigen.hpp"
#include "vrflow/module/start.hpp"
#include "vrflow/rigid/messages.hpp"

int main() {
  using namespace vrflow;
  const std::string program = "vrflow-input-grab";
  Module module;
  const InputPort& objects = module.addInput("objects");
  const InputPort& events = module.addInput("device");
  const OutputPort& forces = module.addOutput("forces");
  if (!initOrReport(module, program)) return 2;
  auto device = input::openModuleDevice(module, program);
  if (!device) return 2;
  input::GrabSpring spring;
  spring.stiffness = module.params().getFloat("stiffness");
  spring.damping = module.params().getFloat("damping");
  spring.maxForce = module.params().getFloat("max-force");
  const auto button = static_cast<std::uint32_t>(module.params().getInt("button"));
  const double fallbackDt = module.params().getFloat("dt");
  rigid::RigidObjectCopy copy;
  struct Held {
    std::uint64_t id = 0;
    Eigen::Vector3d anchor;  ///< body frame
    double distance = 0.0;   ///< along the ray, at the pick
  };
  std::optional<Held> held;
  while (module.wait()) {
    if (const Message& received = module.get(objects); received.valid()) {
      if (auto status = copy.apply(received.view()); !status) {
        std::fprintf(stderr, "%s: %s\n", program.c_str(), status.error().message.c_str());
        return 1;
      }
    }
    const double dt = module.timeStep() > 0 ? module.timeStep() : fallbackDt;
    const double time =
        module.timeStep() > 0 ? module.simTime() : static_cast<double>(module.iteration()) * dt;
    const auto sample = input::nextSample(module, &events, *device, program, time);
    if (!sample) return 1;
    const bool pressed = sample->present && (sample->buttons & (1u << button)) != 0;
    if (!pressed) held.reset();
    if (pressed && !held) {
      std::vector<input::PickTarget> targets;
      for (const auto& [id, entry] : copy.entries())
        if (entry.hasShape && !entry.body.kinematic)
          targets.push_back({id, msg::worldBounds(entry.body.shape, entry.body.position,
                                                  entry.body.orientation)});
      if (const auto hit = input::pick(targets, sample->position, sample->direction)) {
        const auto& body = copy.entries().at(hit->id).body;
        held = Held{hit->id,
                    msg::asEigen(body.orientation).conjugate() *
                        (msg::asEigen(hit->point) - msg::asEigen(body.position)),
                    hit->distance};
      }
    }
    auto out = module.newMessage(256);
    if (held) {
      const auto found = copy.entries().find(held->id);
      if (found == copy.entries().end()) {
        held.reset();  // the object was deleted
      } else {
        const auto& body = found->second.body;
        const Eigen::Vector3d arm = msg::asEigen(body.orientation) * held->anchor;
        const Eigen::Vector3d anchor = msg::asEigen(body.position) + arm;
        const Eigen::Vector3d velocity =
            msg::asEigen(body.linearVelocity) + msg::asEigen(body.angularVelocity).cross(arm);
        const Eigen::Vector3d target =
            msg::asEigen(sample->position) + held->distance * msg::asEigen(sample->direction);
        msg::ForceEvent event;
        event.point = {anchor.x(), anchor.y(), anchor.z()};
        event.force =
            input::grabForce(spring, event.point, {velocity.x(), velocity.y(), velocity.z()},
                             {target.x(), target.y(), target.z()});
        out.builder().addForce(held->id, event);  // duration 0: over the animator's step
      }
    }
    if (!module.put(forces, std::move(out))) break;
  }
  return module.exitStatus();
}
