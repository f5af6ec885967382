#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "vrflow/base/result.hpp"
#include "vrflow/viewer/camera.hpp"

// What one tile of a display wall sees: its off-axis part of the camera's frustum, and the
// axis-aligned box around that part (its volume of interest, as the `route` filter reads it).

namespace vrflow::viewer {

/// One tile of a wall of `cols` x `rows` equal tiles: column `col` from the left, row `row` from
/// the top. The default is the whole view.
struct Tile {
  int col = 0;
  int row = 0;
  int cols = 1;
  int rows = 1;
  bool operator==(const Tile&) const = default;
};

/// Parses "COL ROW COLS ROWS": four integers, 1 <= COLS, ROWS <= 256, 0 <= COL < COLS,
/// 0 <= ROW < ROWS.
Result<Tile> parseTile(std::string_view text);

/// The camera's orthonormal frame: `forward` towards the target, `side` to the right, `up`
/// (the frame gluLookAt builds; when `up` is parallel to the view, z stands in for it).
struct ViewBasis {
  msg::Vec3 forward{}, side{}, up{};
};
/// The frame of `camera`.
ViewBasis viewBasis(const Camera& camera);

/// A frustum as glFrustum takes it: the window at the near plane, in the camera's frame.
struct Frustum {
  double left = 0, right = 0, bottom = 0, top = 0;
  double nearPlane = 0, farPlane = 0;
};

/// The part of the camera's view that `tile` shows, for a tile of `width` x `height` pixels:
/// the whole view is cols*width x rows*height with the camera's vertical field of view, and
/// the tile's window is its share of that view's window at the near plane.
Frustum tileFrustum(const Camera& camera, const Tile& tile, int width, int height);

/// A half-line in the world.
struct Ray {
  msg::Vec3 origin{};     ///< on the near plane
  msg::Vec3 direction{};  ///< unit
};
/// The world ray through window point (`x`, `y`) (pixels from the top-left, continuous: pixel
/// (i, j) spans [i, i+1) x [j, j+1)) of a `width` x `height` window showing `frustum` seen by
/// `camera`: it starts on the near plane and leads away from the eye.
Ray pointerRay(const Camera& camera, const Frustum& frustum, int width, int height, double x,
               double y);

/// Parses "minx miny minz maxx maxy maxz" (finite, min <= max on every axis).
Result<msg::Aabb> parseBox(std::string_view text);
/// "minx miny minz maxx maxy maxz", as the `route` filter reads a volume of interest.
std::string formatBox(const msg::Aabb& box);

/// The axis-aligned box around the part of `frustum` (seen by `camera`) between its near plane
/// and `depth` along the view axis, intersected with `clip` when given: the smallest box
/// around frustum-piece ∩ clip, not the box around the frustum piece cut by clip. nullopt when
/// that intersection is empty.
std::optional<msg::Aabb> viewVolume(const Camera& camera, const Frustum& frustum, double depth,
                                    const std::optional<msg::Aabb>& clip);

}  // namespace vrflow::viewer
