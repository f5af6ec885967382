// massspring/animator: owns one mass-spring net (generated, or loaded from a file) and integrates
// it with internal sub-steps from the forces it receives (see vrflow/massspring/solver.hpp), and
// with the captured users it receives on `users` as kinematic colliders inside those sub-steps
// (vrflow/massspring/user_collider.hpp).
#include <cmath>
#include <cstdio>

#include "common.hpp"
#include "vrflow/camera/user_copy.hpp"
#include "vrflow/massspring/objects.hpp"
#include "vrflow/massspring/solver.hpp"
#include "vrflow/message/builtin_types.hpp"

int main() {
  using namespace vrflow;
  using namespace vrflow::massspring;
  const char* program = "vrflow-massspring-animator";
  Module module;
  // The animator's ports (start.hpp's AnimatorPorts) and the users, optional.
  const AnimatorPorts ports{module.addInput("events"), module.addOutput("objects")};
  const InputPort& usersIn = module.addInput("users");
  if (!initOrReport(module, program)) return 2;
  modules::Params params(module, program);
  StepOptions options;
  options.dt = params.number("dt");
  options.substeps = params.integer("substeps");
  options.internalSprings = params.flag("internal-springs");
  options.constraintIterations = params.integer("constraint-iterations");
  const msg::Vec3 g = params.vec3("gravity");
  options.gravity = {g[0], g[1], g[2]};
  UserColliderMemory userMemory;
  UserColliders colliders;
  colliders.params.thickness = params.number("user-thickness");
  colliders.params.friction = params.number("user-friction");
  colliders.memory = &userMemory;
  if (auto status = validateUserColliderParams(colliders.params); !status)
    params.fail(status.error().message);

  Net net;
  const std::string file = params.text("file");
  if (!file.empty()) {
    auto loaded = loadNet(file);
    if (!loaded)
      params.fail(loaded.error().message);
    else
      net = std::move(*loaded);
  } else {
    GridParams grid;
    grid.n = params.integer("n");
    grid.m = params.integer("m");
    grid.spacing = params.number("spacing");
    grid.mass = params.number("mass");
    grid.stiffness = params.number("stiffness");
    grid.shearFactor = params.number("shear");
    grid.bendFactor = params.number("bend");
    grid.damping = params.number("damping");
    grid.maxStretch = params.number("max-stretch");
    grid.pinCorners = params.flag("pin-corners");
    const msg::Vec3 origin = params.vec3("origin");
    grid.origin = {origin[0], origin[1], origin[2]};
    const auto q = params.numbersIn("orientation", 4);
    grid.orientation = {q[0], q[1], q[2], q[3]};
    if (!params.report()) {
      auto generated = generateGrid(grid);
      if (!generated)
        params.fail(generated.error().message);
      else
        net = std::move(*generated);
    }
  }
  if (auto status = validateStepOptions(options); !status) params.fail(status.error().message);
  const std::string stateFile = params.text("state-file");
  if (params.report()) return 2;

  const std::uint64_t id = module.newId();
  modules::Warnings warnings(program);
  std::vector<double> external(3 * net.nodeCount());
  double totalFreeMass = 0;
  for (std::size_t i = 0; i < net.nodeCount(); ++i) {
    if (!net.pinned[i]) totalFreeMass += net.masses[i];
  }
  // Explicit springs beyond their stability limit (omega h >= 2 on the first state; omega is a
  // lower estimate of that state's, so this never warns wrongly): said once, with the numbers
  // and the way out.
  if (const double omega = fastestSpringFrequency(net); omega > 0) {
    const double h = options.internalSprings ? options.dt / options.substeps : options.dt;
    const int needed = static_cast<int>(std::floor(omega * options.dt / 2.0)) + 1;
    char numbers[160];
    std::snprintf(numbers, sizeof numbers,
                  "the net's fastest spring mode (omega %.4g rad/s) has omega*h %.3g with h %.4g s",
                  omega, omega * h, h);
    const std::string where = "module '" + module.id() + "': ";
    if (omega * h >= 2.0 && !options.internalSprings) {
      warnings.warn(where +
                    "its springs come from an interactor (internal-springs=false), held "
                    "over each outer step: " +
                    numbers +
                    ", beyond the explicit limit omega*h < 2, so the net can blow up; "
                    "use internal-springs=true with substeps >= " +
                    std::to_string(needed) + " and no spring interactor");
    } else if (omega * h >= 2.0) {
      warnings.warn(where + numbers +
                    " (dt / substeps), beyond the explicit limit omega*h < 2, so the net can blow "
                    "up; use substeps >= " +
                    std::to_string(needed));
    }
  }
  double time = 0.0;
  bool warnedStretch = false;
  camera::UserCopy users;
  std::map<std::uint64_t, camera::UserSurface> lastFrames;  // the users the last step met
  while (module.wait()) {
    if (const Message& user = module.get(usersIn); user.valid()) {
      if (auto status = users.apply(user.view()); !status) warnings.warn(status.error().message);
    }
    colliders.users = users.ready();
    std::fill(external.begin(), external.end(), 0.0);
    const Message& received = module.get(ports.events);
    if (received.valid()) {
      for (const auto chunk : received.view()) {
        const auto event = chunk.asEvent();
        if (!event || event->id() != id) continue;
        if (event->isForce()) {
          // A force on the whole net: a uniform acceleration F / (free mass).
          const auto force = event->force();
          if (!force || totalFreeMass <= 0) continue;
          for (std::size_t i = 0; i < net.nodeCount(); ++i) {
            if (net.pinned[i]) continue;
            for (int k = 0; k < 3; ++k)
              external[3 * i + k] += force->force[k] * net.masses[i] / totalFreeMass;
          }
        } else if (event->kind() == kNodeForcesEvent) {
          auto forces = decodeNodeForces(event->payload());
          if (!forces) {
            warnings.warn("ignored an event: " + forces.error().message);
            continue;
          }
          bool inRange = true;
          for (const auto& f : *forces) inRange = inRange && f.node < net.nodeCount();
          if (!inRange) {
            warnings.warn("ignored a node forces event naming a node beyond the net's " +
                          std::to_string(net.nodeCount()) + " nodes");
            continue;
          }
          for (const auto& f : *forces) {
            for (int k = 0; k < 3; ++k) external[3 * f.node + k] += f.force[k];
          }
        }
      }
    }
    if (module.iteration() > 0) {
      colliders.previous.clear();
      for (const auto& [userId, frame] : lastFrames) colliders.previous[userId] = &frame;
      const double worst = step(net, external, options, &colliders);
      if (worst > 1 + 1e-6 && !warnedStretch) {
        warnedStretch = true;
        warnings.warn("a spring is beyond its maximum stretch (worst length/limit " +
                      std::to_string(worst) +
                      "): the net started beyond its limits; the projection pulls it back over the "
                      "next steps");
      }
      time += options.dt;
      lastFrames.clear();
      for (const auto& [userId, frame] : colliders.users) lastFrames.emplace(userId, *frame);
    }
    auto out = module.newMessage(
        256 + net.nodeCount() * 56 +
        (module.iteration() == 0
             ? net.springs.size() * 40 + net.surface.size() * 4 + net.nodeCount() * 9
             : 0));
    auto& builder = out.builder();
    builder.setSimTime(time);
    builder.setTimeStep(options.dt);
    writeNet(builder, id, net, module.iteration() == 0);
    if (!module.put(ports.objects, std::move(out))) break;
  }
  if (!stateFile.empty()) {
    if (auto status = saveNet(net, stateFile); !status) {
      std::fprintf(stderr, "%s: %s\n", program, status.error().message.c_str());
      return 1;
    }
  }
  return module.exitStatus();
}
