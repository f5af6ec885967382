#pragma once

#include <cstdint>
#include <vector>

// Edge blending of a wall tile: the drawn frame multiplied by the tile's blend mask.

namespace vrflow::viewer {

/// Multiplies the current GL colour buffer (width*k x height*k) by `mask` (width x height bytes,
/// rows from the top, 255 = keep), each mask pixel covering k x k drawn pixels.
void applyBlendMask(const std::vector<std::uint8_t>& mask, int width, int height, int k);

}  // namespace vrflow::viewer
