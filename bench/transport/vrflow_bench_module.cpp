// vrflow-bench-peer: the module side of the vrflow-shm transport benchmark.
//   role=ping  sends `size` bytes, waits for the echo, records round trips (after `warmup`)
//   role=pong  echoes what it receives (forwarding the same shared-memory block)
//   role=send  streams `count` messages as fast as backpressure allows
//   role=recv  counts them and records the rate (after `warmup` messages)
// The payload is written into shared memory once and then re-sent by handle, as a producer
// that builds its output in place would: what is measured is the transport, not memcpy.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <vector>

#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

namespace {

int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

int main() {
  vrflow::Module module;
  auto& in = module.addInput("in");
  auto& out = module.addOutput("out");
  if (!initOrReport(module, "vrflow-bench-peer")) return 2;
  const std::string role = module.params().getString("role");
  const auto size = static_cast<std::size_t>(module.params().getInt("size"));
  const auto warmup = static_cast<uint64_t>(module.params().getInt("warmup"));
  const std::string results = module.params().getString("results");
  const auto count = static_cast<uint64_t>(module.params().getInt("count"));  // 0: until input ends

  // The payload, built once in shared memory.
  auto build = [&]() -> vrflow::Result<vrflow::Message> {
    std::vector<std::byte> bytes(size, std::byte{7});
    auto message = module.newMessage(size + 256);
    message.builder().addRawResource(1, true, bytes);
    return module.seal(std::move(message));
  };

  if (role == "pong") {
    while (module.wait()) {
      if (!module.put(out, module.get(in))) break;
    }
    return module.exitStatus();
  }
  if (role == "ping") {
    auto payload = build();
    if (!payload) {
      std::fprintf(stderr, "vrflow-bench-peer: %s\n", payload.error().message.c_str());
      return 2;
    }
    std::vector<int64_t> samples;
    int64_t sentAt = 0;
    while ((count == 0 || module.iteration() < count) && module.wait()) {
      const int64_t now = nowNs();
      if (module.iteration() > warmup) samples.push_back(now - sentAt);
      sentAt = nowNs();
      if (!module.put(out, *payload)) break;
    }
    std::ofstream file(results);
    for (const auto s : samples) file << s << "\n";
    return file ? 0 : 2;
  }
  if (role == "send") {
    auto payload = build();
    if (!payload) {
      std::fprintf(stderr, "vrflow-bench-peer: %s\n", payload.error().message.c_str());
      return 2;
    }
    while ((count == 0 || module.iteration() < count) && module.wait()) {
      if (!module.put(out, *payload)) break;
    }
    return module.exitStatus();
  }
  if (role == "recv") {
    uint64_t received = 0;
    int64_t start = 0;
    int64_t end = 0;
    while (module.wait()) {
      ++received;
      if (received == warmup + 1) start = nowNs();
      end = nowNs();
    }
    const uint64_t timed = received > warmup + 1 ? received - warmup - 1 : 0;
    std::ofstream file(results);
    file << (timed > 0 ? static_cast<double>(timed) * 1e9 / static_cast<double>(end - start) : 0.0)
         << "\n";
    return file ? 0 : 2;
  }
  std::fprintf(stderr, "vrflow-bench-peer: unknown role '%s'\n", role.c_str());
  return 2;
}
