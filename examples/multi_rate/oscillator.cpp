// multirate/oscillator: one point of mass m on a spring of stiffness k to the origin along x,
// integrated with semi-implicit Euler (v += -k/m x h; x += v h). Each message on `clock` is one
// step whose length h is the message's time step stamp (the `dt` parameter when it has none);
// the state after the step leaves on `state`, stamped with simulation time t + h and step h.
// The scheme is stable only for h < 2 / sqrt(k/m): a stiff spring needs small steps.
#include <cstdio>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& clock = module.addInput("clock");
  auto& state = module.addOutput("state");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "multirate-oscillator: %s\n", status.error().message.c_str());
    return 2;
  }
  const double k = module.params().getFloat("stiffness");
  const double m = module.params().getFloat("mass");
  const double fallback = module.params().getFloat("dt");
  double x = module.params().getFloat("x0");
  double v = 0;
  const uint64_t id = module.newId();
  while (module.wait()) {
    (void)module.get(clock);
    const double h = module.timeStep() > 0 ? module.timeStep() : fallback;
    v += -k / m * x * h;
    x += v * h;
    auto out = module.newMessage();
    auto& builder = out.builder();
    builder.setSimTime(module.simTime() + h);
    builder.setTimeStep(h);
    builder
        .addObject(id, msg::pointType(),
                   module.iteration() == 0 ? msg::ObjectOp::Add : msg::ObjectOp::Update)
        .set(msg::PointParam::kPosition, msg::Vec3{x, 0, 0})
        .set(msg::PointParam::kVelocity, msg::Vec3{v, 0, 0})
        .set(msg::PointParam::kMass, m);
    if (!module.put(state, std::move(out))) break;
  }
  return module.exitStatus();
}
