// testing/rebuild: for each message, rebuilds every raw resource from the parts that scatter
// by=size made (a 16-byte header: u64 offset, u64 total, little-endian; then the bytes) and
// checks it against testing/mixed's payload (the iteration counter, then byte i = (7 i +
// iteration) mod 256). Writes `iteration,parts,total,ok` per message to `file`.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <vector>

#include "vrflow/module/module.hpp"

namespace {
uint64_t readU64(const std::byte* p) {
  uint64_t v = 0;
  for (int b = 7; b >= 0; --b) v = (v << 8) | static_cast<uint64_t>(p[b]);
  return v;
}
}  // namespace

int main() {
  using namespace vrflow;
  Module module;
  auto& in = module.addInput("in");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  std::ofstream csv(module.params().getString("file"));
  if (!csv) return 2;
  csv << "iteration,parts,total,ok\n";
  while (module.wait()) {
    const Message& message = module.get(in);
    std::map<uint64_t, std::vector<std::byte>> resources;
    std::map<uint64_t, std::vector<bool>> covered;
    std::size_t parts = 0;
    bool ok = true;
    for (const auto chunk : message.view()) {
      const auto resource = chunk.asResource();
      if (!resource) continue;
      const auto raw = resource->raw();
      if (raw.size() < 16) {
        ok = false;
        continue;
      }
      ++parts;
      const uint64_t offset = readU64(raw.data()), total = readU64(raw.data() + 8);
      auto& bytes = resources[resource->id()];
      auto& seen = covered[resource->id()];
      if (bytes.empty()) {
        bytes.resize(total);
        seen.assign(total, false);
      }
      if (bytes.size() != total || offset + (raw.size() - 16) > total) {
        ok = false;
        continue;
      }
      for (std::size_t i = 16; i < raw.size(); ++i) {
        if (seen[offset + i - 16]) ok = false;
        seen[offset + i - 16] = true;
        bytes[offset + i - 16] = raw[i];
      }
    }
    uint64_t total = 0;
    long iteration = -1;
    for (const auto& [id, bytes] : resources) {
      total += bytes.size();
      for (const bool b : covered[id]) ok = ok && b;
      if (bytes.size() < 8) {
        ok = false;
        continue;
      }
      uint64_t it = 0;
      std::memcpy(&it, bytes.data(), 8);
      iteration = static_cast<long>(it);
      for (std::size_t i = 8; i < bytes.size(); ++i) {
        if (bytes[i] != static_cast<std::byte>((7 * i + it) & 0xff)) ok = false;
      }
    }
    csv << iteration << "," << parts << "," << total << "," << (ok ? "ok" : "bad") << "\n";
    csv.flush();
  }
  return 0;
}
