// testing/misread: reads a parameter its manifest does not declare (what=undeclared) or reads a
// declared one as another type (what=wrong-type); the module API must stop it with a message.
#include <cstdio>

#include "vrflow/module/module.hpp"

int main() {
  vrflow::Module module;
  auto& in = module.addInput("in");
  auto& out = module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const bool undeclared = module.params().getString("what") == "undeclared";
  const double value = undeclared ? static_cast<double>(module.params().getInt("not-declared"))
                                  : module.params().getFloat("what");
  std::printf("misread: read %g without an error\n", value);
  while (module.wait()) {
    if (!module.put(out, module.get(in))) break;
  }
  return module.exitStatus();
}
