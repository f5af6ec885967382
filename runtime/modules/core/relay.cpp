// core/relay: forwards each message it receives; the bytes are not copied.
#include <cstdio>

#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& in = module.addInput("in");
  auto& out = module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "vrflow-core-relay: %s\n", status.error().message.c_str());
    return 2;
  }
  while (module.wait()) {
    if (!module.put(out, module.get(in))) break;
  }
  return module.exitStatus();
}
