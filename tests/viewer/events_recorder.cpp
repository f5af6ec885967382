// viewer-testing/events: writes every input event it receives as one text line to `file`
// ("pointer ACTION BUTTON BUTTONS X Y OX OY OZ DX DY DZ" or "key KEY ACTION"), flushed at once, so
// a test can watch a window's events arrive through a run.
#include <cstdio>

#include "vrflow/message/input_events.hpp"
#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& in = module.addInput("events");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const std::string path = module.params().getString("file");
  std::FILE* out = std::fopen(path.c_str(), "w");
  if (!out) {
    std::fprintf(stderr, "viewer-testing/events: cannot write '%s'\n", path.c_str());
    return 2;
  }
  while (module.wait()) {
    for (const auto chunk : module.get(in).view()) {
      const auto event = chunk.asEvent();
      if (!event) continue;
      if (const auto p = msg::pointerEvent(*event)) {
        std::fprintf(out, "pointer %u %u %u %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n",
                     static_cast<unsigned>(p->action), static_cast<unsigned>(p->button), p->buttons,
                     p->x, p->y, p->rayOrigin[0], p->rayOrigin[1], p->rayOrigin[2],
                     p->rayDirection[0], p->rayDirection[1], p->rayDirection[2]);
      } else if (const auto k = msg::keyEvent(*event)) {
        std::fprintf(out, "key %d %u\n", k->key, static_cast<unsigned>(k->action));
      }
    }
    std::fflush(out);
  }
  std::fclose(out);
  return module.exitStatus();
}
