#include <chrono>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

// vrflow-bench-python-sink: notes when each message arrives and how long after its source sent
// it (the send stamp travels unchanged through a pass-through that forwards by reference), and
// writes them to `out` as it ends: "RECEIVE_NS LATENCY_NS" per message.
int main() {
  vrflow::Module module;
  auto& in = module.addInput("in");
  if (!vrflow::initOrReport(module, "vrflow-bench-python-sink")) return 2;
  const std::string file = module.params().getString("out");
  struct Arrival {
    uint64_t receiveNs, latencyNs;
  };
  std::vector<Arrival> arrivals;
  while (module.wait()) {
    const auto now = static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                               std::chrono::system_clock::now().time_since_epoch())
                                               .count());
    const uint64_t sent = module.get(in)->stamps().sendTimeNs;
    arrivals.push_back({now, now > sent ? now - sent : 0});
  }
  std::FILE* out = std::fopen(file.c_str(), "w");
  if (out == nullptr) {
    std::perror(file.c_str());
    return 1;
  }
  for (const Arrival& a : arrivals) {
    std::fprintf(out, "%llu %llu\n", static_cast<unsigned long long>(a.receiveNs),
                 static_cast<unsigned long long>(a.latencyNs));
  }
  std::fclose(out);
  return module.exitStatus();
}
