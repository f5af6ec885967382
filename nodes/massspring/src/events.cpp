#include "vrflow/massspring/events.hpp"

#include <cmath>
#include <cstring>

namespace vrflow::massspring {

std::vector<std::byte> encodeNodeForces(std::span<const NodeForce> forces) {
  std::vector<std::byte> out(8 + forces.size() * kNodeForceRecordSize);
  const auto count = static_cast<std::uint32_t>(forces.size());
  std::memcpy(out.data(), &count, 4);
  for (std::size_t i = 0; i < forces.size(); ++i) {
    std::byte* record = out.data() + 8 + i * kNodeForceRecordSize;
    std::memcpy(record, &forces[i].node, 4);
    std::memcpy(record + 8, forces[i].force.data(), 24);
  }
  return out;
}

Result<std::vector<NodeForce>> decodeNodeForces(std::span<const std::byte> payload) {
  if (payload.size() < 8)
    return makeError("node forces event: payload shorter than its 8-byte header");
  std::uint32_t count = 0;
  std::memcpy(&count, payload.data(), 4);
  if ((payload.size() - 8) / kNodeForceRecordSize != count ||
      (payload.size() - 8) % kNodeForceRecordSize != 0) {
    return makeError("node forces event: header says " + std::to_string(count) +
                     " records but the payload holds " + std::to_string(payload.size() - 8) +
                     " bytes after it (32 per record)");
  }
  std::vector<NodeForce> forces(count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::byte* record = payload.data() + 8 + i * kNodeForceRecordSize;
    std::memcpy(&forces[i].node, record, 4);
    std::memcpy(forces[i].force.data(), record + 8, 24);
    for (double f : forces[i].force) {
      if (!std::isfinite(f))
        return makeError("node forces event: non-finite force on node " +
                         std::to_string(forces[i].node));
    }
  }
  return forces;
}

std::vector<NodeForce> sparseForces(std::span<const double> dense) {
  std::vector<NodeForce> out;
  for (std::size_t i = 0; i + 2 < dense.size(); i += 3) {
    if (dense[i] != 0 || dense[i + 1] != 0 || dense[i + 2] != 0) {
      out.push_back({static_cast<std::uint32_t>(i / 3), {dense[i], dense[i + 1], dense[i + 2]}});
    }
  }
  return out;
}

}  // namespace vrflow::massspring
