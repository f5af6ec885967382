// testing/orders: one empty message per iteration i with user stamp iteration = offset + i * step,
// for a stampfilter's order port. Ends after `count` iterations (0: never).
#include <cstdio>

#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& out = module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const int64_t step = module.params().getInt("step");
  const int64_t offset = module.params().getInt("offset");
  const auto count = static_cast<uint64_t>(module.params().getInt("count"));
  // wait() only for an iteration it will do: leaving the loop counts the one in progress.
  for (uint64_t done = 0; (count == 0 || done < count) && module.wait(); ++done) {
    const uint64_t it = module.iteration();
    auto message = module.newMessage();
    message.builder().addInt64Stamp("iteration", offset + static_cast<int64_t>(it) * step);
    if (!module.put(out, std::move(message))) break;
  }
  return 0;
}
