// testing/mute: takes every message and never sends one.
#include <cstdio>

#include "vrflow/module/module.hpp"

int main() {
  vrflow::Module module;
  module.addInput("in");
  module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  while (module.wait()) {
  }
  return 0;
}
