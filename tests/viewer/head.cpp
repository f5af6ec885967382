// viewer-testing/head: a tracked head for the wall tests: one `point` object at `position`,
// added at iteration 0 and updated each iteration (same place), for `count` iterations.
#include <cstdio>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& out = module.addOutput("objects");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const auto count = static_cast<std::uint64_t>(module.params().getInt("count"));
  const msg::Vec3 position = module.params().getVec3("position");
  const std::uint64_t id = module.newId();
  for (std::uint64_t done = 0; done < count && module.wait(); ++done) {
    auto message = module.newMessage();
    message.builder()
        .addObject(id, msg::pointType(),
                   module.iteration() == 0 ? msg::ObjectOp::Add : msg::ObjectOp::Update)
        .set(msg::PointParam::kPosition, position);
    if (!module.put(out, std::move(message))) break;
  }
  return module.exitStatus();
}
