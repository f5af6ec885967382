// rigid/animator: owns the rigid bodies of a scene file and/or a generator, integrates the force
// events it receives (semi-implicit Euler, world-frame torques with the rotated inertia) and
// sends an add chunk and the shape resource of every body on the first iteration, then update
// chunks only for the bodies, and the parameters, that changed.
#include "vrflow/rigid/animator.hpp"

#include <cstdio>
#include <map>

#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"
#include "vrflow/rigid/messages.hpp"
#include "vrflow/rigid/scene.hpp"

int main() {
  using namespace vrflow;
  Module module;
  const auto ports = startAnimator(module, "vrflow-rigid-animator");
  if (!ports) return 2;
  const double dt = module.params().getFloat("dt");
  if (!(dt > 0)) {
    std::fprintf(stderr, "vrflow-rigid-animator: dt must be positive\n");
    return 2;
  }
  std::vector<rigid::Body> bodies;
  const std::string scenePath = module.params().getString("scene");
  const std::string generator = module.params().getString("generate");
  if (scenePath.empty() && generator.empty()) {
    std::fprintf(stderr, "vrflow-rigid-animator: set the 'scene' or the 'generate' parameter\n");
    return 2;
  }
  // The scene file's bodies first, then the generated ones.
  for (const bool fromFile : {true, false}) {
    const std::string& spec = fromFile ? scenePath : generator;
    if (spec.empty()) continue;
    auto loaded = fromFile ? rigid::loadScene(spec) : rigid::generateScene(spec);
    if (!loaded) {
      std::fprintf(stderr, "vrflow-rigid-animator: %s\n", loaded.error().message.c_str());
      return 2;
    }
    bodies.insert(bodies.end(), loaded->begin(), loaded->end());
  }
  rigid::RigidAnimatorState state;
  rigid::SleepParams sleep;
  sleep.enabled = module.params().getBool("sleep");
  state.setSleep(sleep);
  std::map<std::uint64_t, std::uint64_t> shapeIds;
  for (auto& body : bodies) {
    body.id = module.newId();
    shapeIds[body.id] = module.newId();
    if (auto status = state.addBody(body); !status) {
      std::fprintf(stderr, "vrflow-rigid-animator: %s\n", status.error().message.c_str());
      return 2;
    }
  }
  std::uint64_t steps = 0;
  while (module.wait()) {
    const Message& received = module.get(ports->events);
    if (received.valid()) {
      for (const auto chunk : received.view()) {
        const auto event = chunk.asEvent();
        if (!event || !event->isForce()) continue;
        if (const auto force = event->force()) state.applyForce(event->id(), *force);
      }
    }
    std::vector<rigid::Change> changes;
    if (module.iteration() > 0) {
      changes = state.step(dt);
      ++steps;
    }
    auto out = module.newMessage(
        256 + (module.iteration() == 0 ? state.bodies().size() * 512 : changes.size() * 200));
    auto& builder = out.builder();
    builder.setSimTime(state.time());
    builder.setTimeStep(dt);
    if (module.iteration() == 0) {
      for (const auto& body : state.bodies()) rigid::writeAdd(builder, body, shapeIds[body.id]);
    } else {
      for (const auto& change : changes)
        rigid::writeUpdate(builder, *state.find(change.id), change);
    }
    if (!module.put(ports->objects, std::move(out))) break;
  }
  if (const auto path = module.params().getString("state-file"); !path.empty()) {
    std::FILE* file = std::fopen(path.c_str(), "w");
    if (!file) {
      std::fprintf(stderr, "vrflow-rigid-animator: cannot write the state file %s\n", path.c_str());
      return 1;
    }
    auto vec = [&](const char* key, const double* v, int n) {
      std::fprintf(file, ", \"%s\": [", key);
      for (int i = 0; i < n; ++i) std::fprintf(file, "%s%.17g", i ? ", " : "", v[i]);
      std::fprintf(file, "]");
    };
    std::fprintf(file, "{\"time\": %.17g, \"steps\": %llu, \"bodies\": [", state.time(),
                 static_cast<unsigned long long>(steps));
    for (std::size_t i = 0; i < state.bodies().size(); ++i) {
      const auto& b = state.bodies()[i];
      std::fprintf(file, "%s\n  {\"id\": %llu, \"kinematic\": %s", i ? "," : "",
                   static_cast<unsigned long long>(b.id), b.kinematic ? "true" : "false");
      vec("position", b.position.data(), 3);
      vec("orientation", b.orientation.data(), 4);
      vec("linearVelocity", b.linearVelocity.data(), 3);
      vec("angularVelocity", b.angularVelocity.data(), 3);
      const auto bounds = msg::worldBounds(b.shape, b.position, b.orientation);
      vec("boundsMin", bounds.min.data(), 3);
      vec("boundsMax", bounds.max.data(), 3);
      std::fprintf(file, "}");
    }
    std::fprintf(file, "\n]}\n");
    std::fclose(file);
  }
  return module.exitStatus();
}
