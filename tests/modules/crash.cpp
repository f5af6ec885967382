// testing/crash: forwards its input, then fails at a chosen iteration (exit status or signal).
#include <csignal>
#include <cstdio>
#include <cstdlib>

#include "vrflow/module/module.hpp"

int main() {
  vrflow::Module module;
  auto& in = module.addInput("in");
  auto& out = module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const auto at = static_cast<uint64_t>(module.params().getInt("at"));
  const int status = static_cast<int>(module.params().getInt("status"));
  const int sig = static_cast<int>(module.params().getInt("signal"));
  while (module.wait()) {
    if (module.iteration() == at) {
      if (sig != 0) std::raise(sig);
      std::_Exit(status);
    }
    if (in.connected()) {
      if (!module.put(out, module.get(in))) break;
    } else if (!module.put(out, module.newMessage())) {
      break;
    }
  }
  return module.exitStatus();
}
