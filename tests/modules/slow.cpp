// testing/slow: a worker. Sleeps `delay-ms` per iteration, then forwards its input by reference
// (`copy` false: the stamps stay the sender's) or as a new message of its own holding the same
// chunks (`copy` true: its own stamps, iteration counted from 0). `stop-at-exit`: once it has
// ended it stops itself (SIGSTOP) before exiting, as a sanitizer's leak check stops an exiting
// process under its tracer.
#include <chrono>
#include <csignal>
#include <cstdio>
#include <thread>

#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& in = module.addInput("in");
  auto& out = module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const auto delay = std::chrono::milliseconds(module.params().getInt("delay-ms"));
  const bool copy = module.params().getBool("copy");
  const bool stopAtExit = module.params().getBool("stop-at-exit");
  while (module.wait()) {
    std::this_thread::sleep_for(delay);
    const Message& received = module.get(in);
    if (!copy) {
      if (!module.put(out, received)) break;
      continue;
    }
    auto message = module.newMessage(received->bytes().size() + 256);
    message.builder().appendChunks(received.view());
    if (!module.put(out, std::move(message))) break;
  }
  if (stopAtExit) std::raise(SIGSTOP);
  return 0;
}
