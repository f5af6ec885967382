#include "vrflow/viewer/view_volume.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <vector>

#include "vrflow/message/eigen.hpp"

namespace vrflow::viewer {
namespace {

constexpr double kPi = 3.14159265358979323846;

using msg::asEigen;

using Polygon = std::vector<msg::Vec3>;

// Sutherland-Hodgman: the part of a convex polygon where sign * (p[axis] - bound) >= 0.
Polygon clip(const Polygon& polygon, std::size_t axis, double bound, double sign) {
  Polygon out;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const msg::Vec3& a = polygon[i];
    const msg::Vec3& b = polygon[(i + 1) % polygon.size()];
    const double da = sign * (a[axis] - bound);
    const double db = sign * (b[axis] - bound);
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) {
      const double t = da / (da - db);
      msg::Vec3 p{a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t};
      p[axis] = bound;  // exactly on the plane despite rounding
      out.push_back(p);
    }
  }
  return out;
}

}  // namespace

Result<Tile> parseTile(std::string_view text) {
  std::istringstream in{std::string(text)};
  Tile tile;
  std::string extra;
  if (!(in >> tile.col >> tile.row >> tile.cols >> tile.rows) || (in >> extra)) {
    return makeError("expects four integers 'COL ROW COLS ROWS', got '" + std::string(text) + "'");
  }
  if (tile.cols < 1 || tile.rows < 1 || tile.cols > 256 || tile.rows > 256 || tile.col < 0 ||
      tile.row < 0 || tile.col >= tile.cols || tile.row >= tile.rows) {
    return makeError(
        "expects 'COL ROW COLS ROWS' with 1 <= COLS, ROWS <= 256, 0 <= COL < COLS "
        "and 0 <= ROW < ROWS, got '" +
        std::string(text) + "'");
  }
  return tile;
}

ViewBasis viewBasis(const Camera& camera) {
  ViewBasis basis;
  // normalized() leaves a zero vector as it is.
  const Eigen::Vector3d forward = (asEigen(camera.target) - asEigen(camera.eye)).normalized();
  Eigen::Vector3d side = forward.cross(asEigen(camera.up)).normalized();
  if (side.squaredNorm() == 0.0) side = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  basis.forward = msg::toVec3(forward);
  basis.side = msg::toVec3(side);
  basis.up = msg::toVec3(side.cross(forward));
  return basis;
}

Frustum tileFrustum(const Camera& camera, const Tile& tile, int width, int height) {
  Frustum f;
  f.nearPlane = camera.nearPlane;
  f.farPlane = camera.farPlane;
  const double top = camera.nearPlane * std::tan(camera.fovYDegrees * kPi / 360.0);
  const double right =
      top * static_cast<double>(tile.cols * width) / static_cast<double>(tile.rows * height);
  // The whole window spans [-right, right] x [-top, top]; for a 1 x 1 wall these are exact.
  f.left = -right + 2.0 * right * tile.col / tile.cols;
  f.right = -right + 2.0 * right * (tile.col + 1) / tile.cols;
  f.top = top - 2.0 * top * tile.row / tile.rows;
  f.bottom = top - 2.0 * top * (tile.row + 1) / tile.rows;
  return f;
}

Ray pointerRay(const Camera& camera, const Frustum& frustum, int width, int height, double x,
               double y) {
  const ViewBasis b = viewBasis(camera);
  const double wx = frustum.left + (frustum.right - frustum.left) * x / width;
  const double wy = frustum.top - (frustum.top - frustum.bottom) * y / height;
  const Eigen::Vector3d offset =
      asEigen(b.forward) * frustum.nearPlane + asEigen(b.side) * wx + asEigen(b.up) * wy;
  return Ray{msg::toVec3(asEigen(camera.eye) + offset), msg::toVec3(offset.normalized())};
}

Result<msg::Aabb> parseBox(std::string_view text) {
  std::string copy(text);
  std::replace(copy.begin(), copy.end(), ',', ' ');
  std::istringstream in(copy);
  std::array<double, 6> v{};
  std::string extra;
  for (double& x : v) in >> x;
  if (in.fail() || (in >> extra) ||
      !std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); })) {
    return makeError("expects six finite numbers 'minx miny minz maxx maxy maxz', got '" +
                     std::string(text) + "'");
  }
  if (v[0] > v[3] || v[1] > v[4] || v[2] > v[5]) {
    return makeError("expects min <= max on every axis ('minx miny minz maxx maxy maxz'), got '" +
                     std::string(text) + "'");
  }
  return msg::Aabb{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
}

std::string formatBox(const msg::Aabb& box) {
  char text[200];
  std::snprintf(text, sizeof text, "%.9g %.9g %.9g %.9g %.9g %.9g", box.min[0], box.min[1],
                box.min[2], box.max[0], box.max[1], box.max[2]);
  return text;
}

std::optional<msg::Aabb> viewVolume(const Camera& camera, const Frustum& frustum, double depth,
                                    const std::optional<msg::Aabb>& clipBox) {
  const ViewBasis b = viewBasis(camera);
  const double n = frustum.nearPlane;
  const double far = std::max(depth, n);
  // The point of the frustum's edge through window point (x, y) at distance d along the view.
  const auto at = [&](double x, double y, double d) {
    const double k = d / n;
    msg::Vec3 p{};
    for (std::size_t a = 0; a < 3; ++a) {
      p[a] = camera.eye[a] + b.forward[a] * d + b.side[a] * x * k + b.up[a] * y * k;
    }
    return p;
  };
  const double l = frustum.left, r = frustum.right, lo = frustum.bottom, hi = frustum.top;
  // The six faces of the frustum piece, each a convex quad.
  const std::array<Polygon, 6> faces{
      Polygon{at(l, lo, n), at(r, lo, n), at(r, hi, n), at(l, hi, n)},
      Polygon{at(l, lo, far), at(r, lo, far), at(r, hi, far), at(l, hi, far)},
      Polygon{at(l, lo, n), at(l, hi, n), at(l, hi, far), at(l, lo, far)},
      Polygon{at(r, lo, n), at(r, hi, n), at(r, hi, far), at(r, lo, far)},
      Polygon{at(l, lo, n), at(r, lo, n), at(r, lo, far), at(l, lo, far)},
      Polygon{at(l, hi, n), at(r, hi, n), at(r, hi, far), at(l, hi, far)}};

  // The vertices of piece ∩ clip: those on a face of the piece are the vertices of that face
  // clipped by the box; the others are corners of the box inside the piece.
  std::vector<msg::Vec3> points;
  for (Polygon face : faces) {
    if (clipBox) {
      for (std::size_t a = 0; a < 3 && !face.empty(); ++a) {
        face = clip(face, a, clipBox->min[a], 1.0);
        if (!face.empty()) face = clip(face, a, clipBox->max[a], -1.0);
      }
    }
    points.insert(points.end(), face.begin(), face.end());
  }
  if (clipBox) {
    for (int corner = 0; corner < 8; ++corner) {
      const msg::Vec3 p{(corner & 1) ? clipBox->max[0] : clipBox->min[0],
                        (corner & 2) ? clipBox->max[1] : clipBox->min[1],
                        (corner & 4) ? clipBox->max[2] : clipBox->min[2]};
      const Eigen::Vector3d v = asEigen(p) - asEigen(camera.eye);
      const double d = v.dot(asEigen(b.forward));
      if (d < n || d > far) continue;
      const double x = v.dot(asEigen(b.side)) * n / d;
      const double y = v.dot(asEigen(b.up)) * n / d;
      if (x >= l && x <= r && y >= lo && y <= hi) points.push_back(p);
    }
  }
  if (points.empty()) return std::nullopt;
  const double inf = std::numeric_limits<double>::infinity();
  msg::Aabb box{{inf, inf, inf}, {-inf, -inf, -inf}};
  for (const auto& p : points) {
    for (std::size_t a = 0; a < 3; ++a) {
      box.min[a] = std::min(box.min[a], p[a]);
      box.max[a] = std::max(box.max[a], p[a]);
    }
  }
  return box;
}

}  // namespace vrflow::viewer
