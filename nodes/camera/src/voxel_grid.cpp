#include "vrflow/camera/voxel_grid.hpp"

#include <algorithm>
#include <cassert>

namespace vrflow::camera {

std::size_t VoxelGrid::countOccupied() const {
  return static_cast<std::size_t>(std::count(occupied.begin(), occupied.end(), std::uint8_t{1}));
}

double intersectionOverUnion(const VoxelGrid& a, const VoxelGrid& b) {
  assert(a.occupied.size() == b.occupied.size());
  std::size_t both = 0, either = 0;
  for (std::size_t i = 0; i < a.occupied.size(); ++i) {
    both += a.occupied[i] & b.occupied[i];
    either += a.occupied[i] | b.occupied[i];
  }
  return either == 0 ? 1.0 : static_cast<double>(both) / static_cast<double>(either);
}

}  // namespace vrflow::camera
