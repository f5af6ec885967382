#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

// vrflow-bench-python-pass: the C++ pass-through, forwarding each message by reference; the
// Python one is pass.py.
int main() {
  vrflow::Module module;
  auto& in = module.addInput("in");
  auto& out = module.addOutput("out");
  if (!vrflow::initOrReport(module, "vrflow-bench-python-pass")) return 2;
  while (module.wait()) {
    if (!module.put(out, module.get(in))) break;
  }
  return module.exitStatus();
}
