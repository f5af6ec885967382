// core/source: one raw resource chunk per iteration, `size` bytes, the first 8 holding the
// iteration number; stops after `count` iterations (0: runs until the run stops). Used by the
// transport benchmark, the pipeline tests and the filter tests.
#include <cstdio>
#include <cstring>
#include <vector>

#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& out = module.addOutput("out");
  if (!initOrReport(module, "vrflow-core-source")) return 2;
  const auto size = static_cast<std::size_t>(module.params().getInt("size"));
  const auto count = static_cast<uint64_t>(module.params().getInt("count"));
  std::vector<std::byte> payload(size < 8 ? 8 : size);
  const uint64_t resource = module.newId();
  // wait() only for an iteration it will do: leaving the loop counts the one in progress.
  for (uint64_t done = 0; (count == 0 || done < count) && module.wait(); ++done) {
    const uint64_t counter = module.iteration();
    std::memcpy(payload.data(), &counter, sizeof counter);
    auto message = module.newMessage(payload.size() + 256);
    message.builder().addRawResource(resource, true, payload);
    if (!module.put(out, std::move(message))) break;
  }
  return module.exitStatus();
}
