// broadcast/checker: a receiver that writes one CSV line per message: the counter of its first
// raw resource chunk (core/source's first 8 bytes), the chunk's size, and the latency from the
// message's send-time stamp to its arrival here (ns, wall clock of this host).
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& in = module.addInput("in");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "broadcast-checker: %s\n", status.error().message.c_str());
    return 2;
  }
  std::ofstream csv(module.params().getString("file"));
  csv << "counter,size,latency_ns\n";
  while (module.wait()) {
    const auto now = static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                               std::chrono::system_clock::now().time_since_epoch())
                                               .count());
    const Message& message = module.get(in);
    const uint64_t sent = message->stamps().sendTimeNs;
    for (const auto chunk : message.view()) {
      const auto resource = chunk.asResource();
      if (!resource) continue;
      const auto bytes = resource->raw();
      uint64_t counter = 0;
      if (bytes.size() >= 8) std::memcpy(&counter, bytes.data(), 8);
      csv << counter << "," << bytes.size() << "," << (now > sent ? now - sent : 0) << "\n";
      break;
    }
  }
  return module.exitStatus();
}
