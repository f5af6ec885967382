#pragma once
// The signed distance field of a voxel model: an exact Euclidean distance transform, separable
// and linear in the voxel count (Felzenszwalb and Huttenlocher, "Distance transforms of sampled
// functions", 2012: the lower envelope of parabolas along each axis in turn), on integer squared
// distances, each strided axis gathered into contiguous lines (a transposed slice or plane).

#include <cstdint>
#include <vector>

#include "vrflow/camera/voxel_grid.hpp"

namespace vrflow::camera {

/// Squared distance (in voxels^2) from every voxel centre to the nearest centre of a voxel whose
/// occupancy equals `target`; kNoVoxel where the grid has none. `threads` > 1 runs the passes
/// on that many oneTBB threads; every line is computed alone, so the result does not depend on it.
std::vector<float> squaredDistanceTo(const VoxelGrid& grid, std::uint8_t target, int threads = 1);

/// The value squaredDistanceTo gives when no voxel has the target occupancy.
inline constexpr float kNoVoxel = 1e20f;

/// Signed distance (metres) of every voxel centre to the model's surface, negative inside: for a
/// voxel outside, the distance to the nearest inside centre less half a voxel; inside, minus the
/// distance to the nearest outside centre less half a voxel (the surface lies half-way between
/// an inside and an outside centre). Voxels beyond the grid count as outside. `threads`: as above.
std::vector<float> signedDistanceField(const VoxelGrid& grid, int threads = 1);

/// The signed distance field where the interactors read it: every value equals
/// min(signedDistanceField(grid), float(band)) bit for bit (exact inside the body and up to
/// `band` metres outside it, `band` beyond), and kNoVoxel everywhere when nothing is occupied.
/// The outside transform runs only over the occupied voxels' box grown by the band, so it costs
/// what the band holds, not the grid. `band` >= 0 (+infinity gives signedDistanceField).
std::vector<float> signedDistanceFieldInBand(const VoxelGrid& grid, double band, int threads = 1);

/// The band a field needs so that a reader that keeps only distances below `reach` (m) and
/// samples the field trilinearly, with the normal from differences half a voxel apart
/// (UserSurface), reads the same values as from the whole field: `reach` plus the 2 sqrt(3)
/// voxels between the cells those samples touch (the field changes by at most the distance
/// between two centres).
double fieldBandFor(double reach, const GridSpec& spec);

}  // namespace vrflow::camera
