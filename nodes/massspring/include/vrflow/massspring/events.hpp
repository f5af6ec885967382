#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "vrflow/base/result.hpp"
// object_type.hpp before values.hpp: its ParamKind enumerators would otherwise shadow msg::Vec3
// (-Wshadow).
#include "vrflow/message/object_type.hpp"
#include "vrflow/message/values.hpp"

// The "massspring node forces" user event: forces on individual nodes of one mass-spring object,
// applied by its animator for the event's outer step (held constant over the internal
// sub-steps). Any package may send it (the spring, collision and rigid/mass-spring interactors,
// the fluid). The event's target id is the net's object id.
//
// Payload (little-endian, packed, 8-byte aligned records):
//   u32 count, u32 reserved (0)
//   count records of 32 bytes: u32 node, u32 reserved (0), f64 fx, f64 fy, f64 fz
// Forces on the same node add up; a node index out of range makes the animator reject the event
// (it logs it once and ignores the event). A plain ForceEvent targeted at a net is also accepted:
// its force is shared among the free nodes in proportion to their mass (a uniform acceleration
// F / total mass, e.g. gravity from a force field); its torque is ignored.

namespace vrflow::massspring {

inline constexpr std::uint16_t kNodeForcesEvent = 1025;
inline constexpr std::size_t kNodeForceRecordSize = 32;

struct NodeForce {
  std::uint32_t node = 0;
  msg::Vec3 force{};
  bool operator==(const NodeForce&) const = default;
};

std::vector<std::byte> encodeNodeForces(std::span<const NodeForce> forces);
Result<std::vector<NodeForce>> decodeNodeForces(std::span<const std::byte> payload);

/// The non-zero entries of a dense xyz-per-node force array, in node order.
std::vector<NodeForce> sparseForces(std::span<const double> dense);

}  // namespace vrflow::massspring
