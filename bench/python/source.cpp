#include <cstddef>

#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

// vrflow-bench-python-source: one message per iteration holding a raw resource of `bytes` bytes,
// written in place in shared memory (only its first byte is touched: the benchmark measures
// the transport, not the filling).
int main() {
  vrflow::Module module;
  auto& out = module.addOutput("out");
  if (!vrflow::initOrReport(module, "vrflow-bench-python-source")) return 2;
  const auto bytes = static_cast<std::size_t>(module.params().getInt("bytes"));
  while (module.wait()) {
    auto message = module.newMessage(bytes + 256);
    const auto body = message.builder().addRawResourceInPlace(1, true, bytes);
    if (!body.empty()) body[0] = std::byte{1};
    if (!module.put(out, std::move(message))) break;
  }
  return module.exitStatus();
}
