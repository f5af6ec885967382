// testing/hog: a module whose memory grows without bound, `step-mib` MiB (touched) per
// iteration, never freed; `max-mib` (0: none) is a safety net for machines without a cap.
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& out = module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const auto step = static_cast<std::size_t>(module.params().getInt("step-mib")) << 20;
  const auto max = static_cast<std::size_t>(module.params().getInt("max-mib")) << 20;
  std::vector<std::unique_ptr<char[]>> held;
  while (module.wait()) {
    if (max == 0 || held.size() * step < max) {
      held.push_back(std::make_unique<char[]>(step));  // value-initialized: every page touched
    }
    if (!module.put(out, module.newMessage(64))) break;
  }
  return 0;
}
