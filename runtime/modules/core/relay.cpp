// core/relay: forwards each message it receives; the bytes are not copied. With `delay-ms`
// > 0 it sleeps that long before forwarding each message (a slow worker, for examples).
#include <chrono>
#include <cstdio>
#include <thread>

#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& in = module.addInput("in");
  auto& out = module.addOutput("out");
  if (!initOrReport(module, "vrflow-core-relay")) return 2;
  const auto delay = std::chrono::milliseconds(module.params().getInt("delay-ms"));
  while (module.wait()) {
    if (delay.count() > 0) std::this_thread::sleep_for(delay);
    if (!module.put(out, module.get(in))) break;
  }
  return module.exitStatus();
}
