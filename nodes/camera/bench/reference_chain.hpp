#pragma once
// The camera chain's stages as they were before the speed round of issue 21 (single-threaded:
// the distance field on float lines gathered at their stride, the mesh over every cube with a
// hash map of vertices, the carving visiting 16^3 blocks through projected corners), kept
// callable for vrflow-bench-camera's before/after in one run and for the tests that check that
// the new code gives the same bits.

#include <cstdint>
#include <vector>

#include "vrflow/camera/hull_mesh.hpp"
#include "vrflow/camera/visual_hull.hpp"
#include "vrflow/camera/voxel_grid.hpp"

namespace vrflow::camera::reference {

/// squaredDistanceTo as it was.
std::vector<float> squaredDistanceTo(const VoxelGrid& grid, std::uint8_t target);
/// signedDistanceField as it was.
std::vector<float> signedDistanceField(const VoxelGrid& grid);
/// meshHull as it was.
TriangleMesh meshHull(const VoxelGrid& grid, const std::vector<float>& sdf);
/// carveVisualHull over the whole grid as it was; the views are checked by the caller.
void carveVisualHull(const std::vector<MaskView>& views, VoxelGrid& hull);

}  // namespace vrflow::camera::reference
