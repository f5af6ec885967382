// testing/toggle: control messages for a gate, one per iteration, following `pattern` (cycled):
// '1' a message with one chunk, '0' an empty message, 'o' an empty message with user stamp
// open=1, 'c' a message with one chunk and user stamp open=0. Ends after `count` iterations
// (0: never).
#include <cstdio>
#include <string>

#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& out = module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const std::string pattern = module.params().getString("pattern");
  const auto count = static_cast<uint64_t>(module.params().getInt("count"));
  const uint64_t resource = module.newId();
  // wait() only for an iteration it will do: leaving the loop counts the one in progress.
  for (uint64_t done = 0; ((count == 0 || done < count) && !pattern.empty()) && module.wait();
       ++done) {
    const uint64_t it = module.iteration();
    const char token = pattern[it % pattern.size()];
    auto message = module.newMessage();
    if (token == '1' || token == 'c') message.builder().addRawResource(resource, true, {});
    if (token == 'o') message.builder().addInt64Stamp("open", 1);
    if (token == 'c') message.builder().addInt64Stamp("open", 0);
    if (!module.put(out, std::move(message))) break;
  }
  return 0;
}
