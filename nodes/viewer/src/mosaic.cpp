#include "vrflow/viewer/mosaic.hpp"

#include <algorithm>
#include <cmath>

namespace vrflow::viewer {
namespace {

// Pixels along one axis between the starts of neighbouring tiles, at the tiles' density.
int pitchPixels(int pixels, double size, double bezel, double overlap) {
  return static_cast<int>(std::lround((size + bezel - overlap) * pixels / size));
}

}  // namespace

Result<Image> stitchWall(const Wall& wall, const std::vector<PlacedImage>& tiles) {
  const int px = pitchPixels(wall.pixelsX, wall.sizeX, wall.bezelX, wall.overlapX);
  const int py = pitchPixels(wall.pixelsY, wall.sizeY, wall.bezelY, wall.overlapY);
  Image out;
  out.width = (wall.cols - 1) * px + wall.pixelsX;
  out.height = (wall.rows - 1) * py + wall.pixelsY;
  std::vector<int> sum(static_cast<std::size_t>(out.width) * out.height * 3, 0);
  for (const auto& tile : tiles) {
    if (tile.image.width != wall.pixelsX || tile.image.height != wall.pixelsY) {
      return makeError("tile at column " + std::to_string(tile.col) + ", row " +
                       std::to_string(tile.row) + " is " + std::to_string(tile.image.width) + "x" +
                       std::to_string(tile.image.height) + " pixels, the wall's are " +
                       std::to_string(wall.pixelsX) + "x" + std::to_string(wall.pixelsY));
    }
    if (tile.col < 0 || tile.row < 0 || tile.col >= wall.cols || tile.row >= wall.rows) {
      return makeError("tile at column " + std::to_string(tile.col) + ", row " +
                       std::to_string(tile.row) + " is outside the wall");
    }
    const int x0 = tile.col * px, y0 = tile.row * py;
    for (int y = 0; y < wall.pixelsY; ++y) {
      const std::uint8_t* from =
          tile.image.rgb.data() + static_cast<std::size_t>(y) * wall.pixelsX * 3;
      int* to = sum.data() + (static_cast<std::size_t>(y0 + y) * out.width + x0) * 3;
      for (int i = 0; i < wall.pixelsX * 3; ++i) to[i] += from[i];
    }
  }
  out.rgb.resize(sum.size());
  std::transform(sum.begin(), sum.end(), out.rgb.begin(),
                 [](int v) { return static_cast<std::uint8_t>(std::min(v, 255)); });
  return out;
}

}  // namespace vrflow::viewer
