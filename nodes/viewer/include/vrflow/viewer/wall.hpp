#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/viewer/camera.hpp"
#include "vrflow/viewer/view_volume.hpp"

// A display wall as a VR lab installs it: a grid of tiles (screens or projectors) on a plane of
// the world, with mullions between screens or overlapping projections blended at their edges,
// seen from a head (tracked) or a fixed eye. Each tile shows the scene through its own piece of
// the plane: an off-axis frustum from the eye through the tile's physical rectangle. The text
// format is described in docs/wall.md.

namespace vrflow::viewer {

/// One tile: where it sits in the grid and which host, X display and window show it.
struct WallTile {
  std::string id;  ///< the viewer module's `wall-tile`
  int col = 0;     ///< from the left
  int row = 0;     ///< from the top
  std::string host;
  std::string display;  ///< X display and screen (":0.1")
  std::string window;   ///< the viewer's `window`: "fullscreen" or "X Y"
  int line = 0;         ///< where it was declared in the file
};

/// The wall: a cols x rows grid of equal tiles on a plane of the world (metres, y up).
struct Wall {
  int cols = 1, rows = 1;
  int pixelsX = 960, pixelsY = 540;       ///< each tile's image
  double sizeX = 1.6, sizeY = 0.9;        ///< each tile's image on the wall (m)
  double bezelX = 0.0, bezelY = 0.0;      ///< mullion: gap between neighbouring images (m)
  double overlapX = 0.0, overlapY = 0.0;  ///< projections shared by neighbours, blended (m)
  double gamma = 1.0;                     ///< display gamma the blend ramps are corrected for
  msg::Vec3 centre{0.0, 1.5, 0.0};        ///< world point of the wall's centre
  msg::Vec3 right{1.0, 0.0, 0.0};         ///< unit, along the rows
  msg::Vec3 up{0.0, 1.0, 0.0};            ///< unit, along the columns; right x up faces the viewer
  msg::Vec3 eye{0.0, 1.5, 3.0};           ///< the fixed eye (when no head position arrives)
  std::vector<WallTile> tiles;

  /// The tile called `id`, or nullptr.
  const WallTile* find(const std::string& id) const;
};

/// Parses the text format (docs/wall.md); errors name `file`:line.
Result<Wall> parseWall(const std::string& text, const std::string& file);
/// Reads and parses a wall file.
Result<Wall> loadWall(const std::string& path);

/// A tile's image on the wall, in world coordinates.
struct TileRect {
  msg::Vec3 lowerLeft{}, lowerRight{}, upperLeft{};
};
/// Where tile (col, row) shows its image.
TileRect tileRect(const Wall& wall, int col, int row);

/// What a tile draws: the eye, looking straight at the wall (camera.target = eye - normal,
/// camera.up = the wall's up), and the off-axis frustum through the tile's rectangle.
struct TileView {
  Camera camera;
  Frustum frustum;
};
/// The head-coupled view of tile (col, row) from `eye` (generalized perspective projection);
/// an error when the eye is not in front of the wall by more than the near plane.
Result<TileView> tileView(const Wall& wall, int col, int row, const msg::Vec3& eye,
                          double nearPlane = 0.05, double farPlane = 500.0);

/// The edge-blending weight (linear light, 0..1) of tile (col, row) at wall point (u, v): metres
/// from the wall's centre along right and up. 1 inside, a smoothstep ramp across each overlap
/// with a neighbour, 0 outside the tile: the weights of all tiles sum to one on the wall.
double blendWeight(const Wall& wall, int col, int row, double u, double v);

/// The tile's blend mask for the renderer: pixelsX x pixelsY bytes, rows from the top, each
/// 255 * weight^(1/gamma) at the pixel's centre. Empty when the wall has no overlap.
std::vector<std::uint8_t> blendMask(const Wall& wall, int col, int row);

}  // namespace vrflow::viewer
