#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"
// object_type.hpp before values.hpp: its ParamKind enumerators would otherwise shadow msg::Vec3
// (-Wshadow).
#include "vrflow/message/object_type.hpp"
#include "vrflow/message/values.hpp"

// A mass-spring net: nodes (mass, position, velocity, pinned flag), springs between nodes and an
// optional triangle surface over the nodes (for drawing and for net/net collision).

namespace vrflow::massspring {

/// One spring. On the wire (the massspring object's `springs` Bytes parameter) a spring is a
/// 40-byte little-endian record, packed, in this order:
///   u32 a, u32 b            node indices (a != b, both < node count)
///   f64 restLength          metres, > 0
///   f64 stiffness           N/m, >= 0
///   f64 damping             N s/m along the spring, >= 0
///   f64 maxStretch          largest allowed length / restLength (>= 1), or 0 for no limit
struct Spring {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  double restLength = 1.0;
  double stiffness = 0.0;
  double damping = 0.0;
  double maxStretch = 0.0;
  bool operator==(const Spring&) const = default;
};
inline constexpr std::size_t kSpringRecordSize = 40;

/// A net's whole state. positions/velocities hold xyz per node.
struct Net {
  std::vector<double> positions;
  std::vector<double> velocities;
  std::vector<double> masses;
  std::vector<std::uint8_t> pinned;  ///< 0 free, 1 pinned (never moves)
  std::vector<Spring> springs;
  std::vector<std::uint32_t> surface;  ///< three node indices per triangle (may be empty)

  std::size_t nodeCount() const { return masses.size(); }
  msg::Vec3 position(std::size_t i) const {
    return {positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]};
  }
  msg::Vec3 velocity(std::size_t i) const {
    return {velocities[3 * i], velocities[3 * i + 1], velocities[3 * i + 2]};
  }
  bool operator==(const Net&) const = default;
};

/// Checks sizes, finite values, positive masses, spring indices and parameters, surface indices.
Status validateNet(const Net& net);

/// The bounding box of the node positions (zero box for an empty net).
msg::Aabb bounds(const Net& net);

/// The generator of rectangular nets: n x m nodes in the body-frame x-z plane, centred on the
/// origin, placed at `origin` with unit quaternion `orientation` (x, y, z, w). Node (i, j) has
/// index j * n + i and sits at body (i * spacing - (n-1) spacing/2, 0, j * spacing - ...).
/// Springs: structural (to (i+1, j) and (i, j+1)), shear (both diagonals of each cell) and bend
/// (to (i+2, j) and (i, j+2)), in that order; the surface has two triangles per cell with body
/// normal +y.
struct GridParams {
  int n = 20;
  int m = 20;
  double spacing = 0.1;
  double mass = 1.0;         ///< total mass of the net (kg), shared equally by the nodes
  double stiffness = 500.0;  ///< structural springs (N/m)
  double shearFactor = 0.5;  ///< shear stiffness = shearFactor * stiffness (0: no shear springs)
  double bendFactor = 0.1;   ///< bend stiffness = bendFactor * stiffness (0: no bend springs)
  double damping = 0.05;     ///< per spring (N s/m)
  double maxStretch = 1.1;   ///< per spring, 0 for none
  bool pinCorners = true;    ///< pin the four corner nodes
  msg::Vec3 origin{0, 0, 0};
  msg::Quat orientation{0, 0, 0, 1};
};
Result<Net> generateGrid(const GridParams& params);

/// Reads a net from a text file (format in nodes/massspring/README.md, "Net files"):
///   massspring 1
///   nodes N           then N lines: x y z mass pinned [vx vy vz]
///   springs S         then S lines: a b restLength stiffness damping maxStretch
///                     (restLength < 0: the nodes' initial distance)
///   triangles T       optional, then T lines: a b c
/// '#' starts a comment. Errors name the file and line.
Result<Net> loadNet(const std::string& path);
/// Parses the same format from a string (`origin` names it in errors).
Result<Net> parseNet(const std::string& text, const std::string& origin = "<text>");
/// Writes the format loadNet reads, every double with 17 significant digits (round trip exact).
Status saveNet(const Net& net, const std::string& path);
std::string formatNet(const Net& net);

/// Spring records to and from the wire layout above.
std::vector<std::byte> encodeSprings(std::span<const Spring> springs);
Result<std::vector<Spring>> decodeSprings(std::span<const std::byte> bytes);
/// Surface indices to and from Bytes (u32 little-endian, three per triangle).
std::vector<std::byte> encodeIndices(std::span<const std::uint32_t> indices);
Result<std::vector<std::uint32_t>> decodeIndices(std::span<const std::byte> bytes);

}  // namespace vrflow::massspring
