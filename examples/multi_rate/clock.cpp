// multirate/clock: the slow outer loop. Iteration i sends an empty message stamped with
// simulation time i*dt and time step dt ("advance from i*dt to (i+1)*dt"); ends after `count`.
// Its optional input `state` closes a loop (the fast module's decimated state back to the slow
// one, as a fluid reads the net it is coupled with): each iteration then waits for one message.
#include <cstdio>

#include "vrflow/module/module.hpp"

int main() {
  vrflow::Module module;
  auto& ticks = module.addOutput("ticks");
  module.addInput("state");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "multirate-clock: %s\n", status.error().message.c_str());
    return 2;
  }
  const double dt = module.params().getFloat("dt");
  const auto count = static_cast<uint64_t>(module.params().getInt("count"));
  // wait() only for an iteration it will do: leaving the loop counts the one in progress.
  for (uint64_t done = 0; (count == 0 || done < count) && module.wait(); ++done) {
    const uint64_t i = module.iteration();
    auto message = module.newMessage();
    message.builder().setSimTime(static_cast<double>(i) * dt);
    message.builder().setTimeStep(dt);
    if (!module.put(ticks, std::move(message))) break;
  }
  return module.exitStatus();
}
