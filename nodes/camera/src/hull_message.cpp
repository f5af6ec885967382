#include "vrflow/camera/hull_message.hpp"

#include <cstring>
#include <string>
#include <vector>

#include "raw_form.hpp"
#include "vrflow/message/packed.hpp"

namespace vrflow::camera {

namespace {
constexpr char kMagic[4] = {'V', 'X', 'H', '1'};
constexpr std::uint32_t kVersion = 1;
}  // namespace

void addHullSlab(msg::MessageBuilder& builder, std::uint64_t resourceId, const VoxelGrid& grid,
                 int zBegin, int zEnd) {
  const GridSpec& s = grid.spec;
  const std::size_t layer = static_cast<std::size_t>(s.nx) * static_cast<std::size_t>(s.ny);
  const std::size_t count = layer * static_cast<std::size_t>(zEnd - zBegin);
  std::vector<std::byte> body(kHullSlabHeaderSize + count);
  std::memcpy(body.data(), kMagic, 4);
  msg::storeRaw(body.data() + 4, kVersion);
  msg::storeRaw(body.data() + 8, std::int32_t{s.nx});
  msg::storeRaw(body.data() + 12, std::int32_t{s.ny});
  msg::storeRaw(body.data() + 16, std::int32_t{s.nz});
  msg::storeRaw(body.data() + 20, std::int32_t{zBegin});
  msg::storeRaw(body.data() + 24, std::int32_t{zEnd});
  for (int a = 0; a < 3; ++a) msg::storeRaw(body.data() + 32 + 8 * a, s.origin[a]);
  msg::storeRaw(body.data() + 56, s.voxelSize);
  if (count > 0)
    std::memcpy(body.data() + kHullSlabHeaderSize,
                grid.occupied.data() + layer * static_cast<std::size_t>(zBegin), count);
  builder.addRawResource(resourceId, true, body);
}

Result<HullSlabView> readHullSlab(const msg::ResourceView& resource) {
  auto checked = rawFormBody(resource, kMagic, kVersion, kHullSlabHeaderSize, "hull slab");
  if (!checked) return checked.error();
  const auto body = *checked;
  const std::string what = "resource " + std::to_string(resource.id()) + ": ";
  HullSlabView slab;
  slab.spec.nx = msg::loadRaw<std::int32_t>(body.data() + 8);
  slab.spec.ny = msg::loadRaw<std::int32_t>(body.data() + 12);
  slab.spec.nz = msg::loadRaw<std::int32_t>(body.data() + 16);
  slab.zBegin = msg::loadRaw<std::int32_t>(body.data() + 20);
  slab.zEnd = msg::loadRaw<std::int32_t>(body.data() + 24);
  for (int a = 0; a < 3; ++a) slab.spec.origin[a] = msg::loadRaw<double>(body.data() + 32 + 8 * a);
  slab.spec.voxelSize = msg::loadRaw<double>(body.data() + 56);
  const GridSpec& s = slab.spec;
  if (s.nx <= 0 || s.ny <= 0 || s.nz <= 0 || s.nx > 4096 || s.ny > 4096 || s.nz > 4096 ||
      !(s.voxelSize > 0) || slab.zBegin < 0 || slab.zEnd < slab.zBegin || slab.zEnd > s.nz)
    return Error{what + "hull slab with an impossible grid or slab range"};
  const std::size_t count = static_cast<std::size_t>(s.nx) * static_cast<std::size_t>(s.ny) *
                            static_cast<std::size_t>(slab.zEnd - slab.zBegin);
  if (body.size() - kHullSlabHeaderSize != count)
    return Error{what + "hull slab holds " + std::to_string(body.size() - kHullSlabHeaderSize) +
                 " occupancy bytes, its header says " + std::to_string(count)};
  slab.occupied = {reinterpret_cast<const std::uint8_t*>(body.data() + kHullSlabHeaderSize), count};
  return slab;
}

Status gatherHullSlab(const HullSlabView& slab, VoxelGrid& grid) {
  const GridSpec& a = slab.spec;
  const GridSpec& b = grid.spec;
  if (a.nx != b.nx || a.ny != b.ny || a.nz != b.nz || a.origin != b.origin ||
      a.voxelSize != b.voxelSize)
    return Error{"hull slab of another grid"};
  const std::size_t layer = static_cast<std::size_t>(a.nx) * static_cast<std::size_t>(a.ny);
  if (!slab.occupied.empty())
    std::memcpy(grid.occupied.data() + layer * static_cast<std::size_t>(slab.zBegin),
                slab.occupied.data(), slab.occupied.size());
  return {};
}

}  // namespace vrflow::camera
