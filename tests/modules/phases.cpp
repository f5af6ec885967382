// testing/phases: logs when each iteration begins and ends, for tests of iteration counts and
// of endIt timing. Each iteration: wait(), append "<id> begin <i>" to `log`, sleep `delay-ms`,
// send a message on `out`, append "<id> end <i>". Runs `count` iterations (0: until the run
// stops) and leaves its loop then, without calling wait() again.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  module.addInput("in");
  auto& out = module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const auto delay = std::chrono::milliseconds(module.params().getInt("delay-ms"));
  const auto count = static_cast<uint64_t>(module.params().getInt("count"));
  std::ofstream log(module.params().getString("log"), std::ios::app);
  const auto note = [&](const char* what) {
    log << module.id() << " " << what << " " << module.iteration() << std::endl;
  };
  for (uint64_t i = 0; count == 0 || i < count; ++i) {
    if (!module.wait()) break;
    note("begin");
    if (delay.count() > 0) std::this_thread::sleep_for(delay);
    if (!module.put(out, module.newMessage())) break;
    note("end");
  }
  return module.exitStatus();
}
