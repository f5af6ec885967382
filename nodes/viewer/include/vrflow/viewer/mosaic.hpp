#pragma once

#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/viewer/image.hpp"
#include "vrflow/viewer/wall.hpp"

// The wall recorder's core: the tiles' images of one iteration joined into the picture the
// whole wall shows, for CI and for people who have no wall.

namespace vrflow::viewer {

/// One tile's image and where it sits.
struct PlacedImage {
  int col = 0;
  int row = 0;
  Image image;
};

/// The wall's picture at the tiles' pixel density: each tile's image where the tile sits on the
/// wall, mullions (bezel) black, overlapping projections added (blended tiles sum to the scene's
/// light). Every image must have the wall's tile size; missing tiles stay black.
Result<Image> stitchWall(const Wall& wall, const std::vector<PlacedImage>& tiles);

}  // namespace vrflow::viewer
