#pragma once
// The visual hull as it travels between modules: a carved z slab [zBegin, zEnd) of an occupancy
// grid (the whole grid is the slab [0, nz)), as one dynamic Raw resource. Hull modules each carve
// a slab and send it; a gather (or the user animator) assembles the slabs of one frame into the
// grid. Body, little-endian: "VXH1" at 0, u32 version (1) at 4, i32 nx, ny, nz at 8, 12, 16,
// i32 zBegin, zEnd at 20, 24, 4 zero bytes, f64 origin[3] at 32, f64 voxelSize at 56, then
// nx * ny * (zEnd - zBegin) bytes of occupancy (0 or 1, x fastest) from 64.

#include <cstdint>
#include <span>

#include "vrflow/base/result.hpp"
#include "vrflow/camera/voxel_grid.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/chunk_views.hpp"

namespace vrflow::camera {

inline constexpr std::size_t kHullSlabHeaderSize = 64;

/// A slab read from a message: the grid it belongs to and a view of its occupancy bytes.
struct HullSlabView {
  GridSpec spec;
  int zBegin = 0, zEnd = 0;
  std::span<const std::uint8_t> occupied;  ///< nx * ny * (zEnd - zBegin) bytes
};

/// Appends slab [zBegin, zEnd) of `grid` as dynamic Raw resource `resourceId`.
void addHullSlab(msg::MessageBuilder& builder, std::uint64_t resourceId, const VoxelGrid& grid,
                 int zBegin, int zEnd);

/// Reads a slab; an error (naming what is wrong) when the resource is not a well-formed slab.
Result<HullSlabView> readHullSlab(const msg::ResourceView& resource);

/// Copies `slab` into `grid`; an error when the slab belongs to another grid.
Status gatherHullSlab(const HullSlabView& slab, VoxelGrid& grid);

}  // namespace vrflow::camera
