#include "vrflow/viewer/wall.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "vrflow/message/eigen.hpp"

namespace vrflow::viewer {
namespace {

using msg::asEigen;

// Where a tile's image starts along one axis of the wall, and the whole wall's extent.
double pitch(double size, double bezel, double overlap) {
  return size + bezel - overlap;
}

double extent(int count, double size, double bezel, double overlap) {
  return count * size + (count - 1) * (bezel - overlap);
}

// The tile's image as [u0, u1] x [v0, v1] in metres from the wall's centre.
struct Span {
  double u0, u1, v0, v1;
};

Span span(const Wall& w, int col, int row) {
  const double width = extent(w.cols, w.sizeX, w.bezelX, w.overlapX);
  const double height = extent(w.rows, w.sizeY, w.bezelY, w.overlapY);
  Span s{};
  s.u0 = -width / 2 + col * pitch(w.sizeX, w.bezelX, w.overlapX);
  s.u1 = s.u0 + w.sizeX;
  s.v1 = height / 2 - row * pitch(w.sizeY, w.bezelY, w.overlapY);
  s.v0 = s.v1 - w.sizeY;
  return s;
}

// 0 at t <= 0, 1 at t >= 1, and s(t) + s(1 - t) = 1 between.
double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// The weight along one axis: ramps up over [lo, lo + overlap] unless first, down over
// [hi - overlap, hi] unless last.
double ramp(double x, double lo, double hi, double overlap, bool first, bool last) {
  if (x < lo || x > hi) return 0.0;
  if (overlap <= 0.0) return 1.0;
  double w = 1.0;
  if (!first) w *= smoothstep((x - lo) / overlap);
  if (!last) w *= smoothstep((hi - x) / overlap);
  return w;
}

// One line's reader: named numbers, with errors naming file:line.
class LineReader {
 public:
  LineReader(std::istringstream& in, std::string where) : in_(in), where_(std::move(where)) {}
  template <typename T>
  bool read(T& value) {
    return static_cast<bool>(in_ >> value);
  }
  bool atEnd() {
    std::string extra;
    return !(in_ >> extra);
  }
  Error error(const std::string& what) const { return makeError(where_ + ": " + what); }

 private:
  std::istringstream& in_;
  std::string where_;
};

bool finite(const msg::Vec3& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

}  // namespace

const WallTile* Wall::find(const std::string& id) const {
  for (const auto& t : tiles) {
    if (t.id == id) return &t;
  }
  return nullptr;
}

Result<Wall> parseWall(const std::string& text, const std::string& file) {
  Wall wall;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  std::set<std::string> seen;
  std::set<std::pair<int, int>> places;
  while (std::getline(lines, line)) {
    ++number;
    const std::string where = file + ":" + std::to_string(number);
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream in(line);
    std::string key;
    if (!(in >> key)) continue;
    LineReader r(in, where);
    const auto pair = [&](auto& a, auto& b, const char* form) -> Status {
      if (!r.read(a) || !r.read(b) || !r.atEnd()) {
        return r.error("'" + key + "' expects " + form + ", got '" + line + "'");
      }
      return {};
    };
    const auto vec = [&](msg::Vec3& v) -> Status {
      if (!r.read(v[0]) || !r.read(v[1]) || !r.read(v[2]) || !r.atEnd() || !finite(v)) {
        return r.error("'" + key + "' expects three finite numbers 'X Y Z', got '" + line + "'");
      }
      return {};
    };
    Status ok;
    if (key == "grid") {
      ok = pair(wall.cols, wall.rows, "'COLS ROWS'");
      if (ok && (wall.cols < 1 || wall.rows < 1 || wall.cols > 256 || wall.rows > 256)) {
        ok = r.error("'grid' expects 1..256 columns and rows, got '" + line + "'");
      }
    } else if (key == "pixels") {
      ok = pair(wall.pixelsX, wall.pixelsY, "'WIDTH HEIGHT' (pixels of one tile)");
      if (ok &&
          (wall.pixelsX < 16 || wall.pixelsY < 16 || wall.pixelsX > 8192 || wall.pixelsY > 8192)) {
        ok = r.error("'pixels' expects 16..8192 each way, got '" + line + "'");
      }
    } else if (key == "size" || key == "bezel" || key == "overlap") {
      double x = 0, y = 0;
      ok = pair(x, y, "'X Y' (metres)");
      const bool positive = key == "size";
      if (ok && (!std::isfinite(x) || !std::isfinite(y) || x < 0 || y < 0 ||
                 (positive && (x <= 0 || y <= 0)))) {
        ok = r.error("'" + key + "' expects two " + (positive ? "positive" : "non-negative") +
                     " finite numbers (metres), got '" + line + "'");
      }
      if (key == "size") wall.sizeX = x, wall.sizeY = y;
      if (key == "bezel") wall.bezelX = x, wall.bezelY = y;
      if (key == "overlap") wall.overlapX = x, wall.overlapY = y;
    } else if (key == "gamma") {
      if (!r.read(wall.gamma) || !r.atEnd() || !(wall.gamma >= 0.5 && wall.gamma <= 5.0)) {
        ok = r.error("'gamma' expects one number in 0.5..5, got '" + line + "'");
      }
    } else if (key == "centre") {
      ok = vec(wall.centre);
    } else if (key == "right") {
      ok = vec(wall.right);
    } else if (key == "up") {
      ok = vec(wall.up);
    } else if (key == "eye") {
      ok = vec(wall.eye);
    } else if (key == "tile") {
      WallTile t;
      t.line = number;
      std::string x, y;
      if (!r.read(t.id) || !r.read(t.col) || !r.read(t.row) || !r.read(t.host) ||
          !r.read(t.display) || !r.read(x)) {
        ok = r.error(
            "'tile' expects 'ID COL ROW HOST DISPLAY fullscreen' or 'ID COL ROW HOST DISPLAY X "
            "Y', got '" +
            line + "'");
      } else if (x == "fullscreen") {
        t.window = x;
        if (!r.atEnd()) ok = r.error("'tile' has extra words after 'fullscreen': '" + line + "'");
      } else if (!r.read(y) || !r.atEnd()) {
        ok = r.error("'tile' expects the window's corner 'X Y' after the display, got '" + line +
                     "'");
      } else {
        t.window = x + " " + y;
      }
      if (ok && !seen.insert(t.id).second) ok = r.error("tile '" + t.id + "' declared twice");
      if (ok && !places.insert({t.col, t.row}).second) {
        ok = r.error("two tiles at column " + std::to_string(t.col) + ", row " +
                     std::to_string(t.row));
      }
      wall.tiles.push_back(t);
    } else {
      ok = r.error("unknown key '" + key +
                   "' (grid, pixels, size, bezel, overlap, gamma, centre, right, up, eye, tile)");
    }
    if (!ok) return ok.error();
  }
  const auto R = asEigen(wall.right), U = asEigen(wall.up);
  if (std::abs(R.norm() - 1.0) > 1e-6 || std::abs(U.norm() - 1.0) > 1e-6 ||
      std::abs(R.dot(U)) > 1e-6) {
    return makeError(file + ": 'right' and 'up' must be orthogonal unit vectors");
  }
  if (wall.bezelX * wall.overlapX > 0 || wall.bezelY * wall.overlapY > 0) {
    return makeError(file + ": a wall has either a bezel or an overlap along an axis, not both");
  }
  if (2 * wall.overlapX > wall.sizeX || 2 * wall.overlapY > wall.sizeY) {
    return makeError(file + ": the overlap must be at most half a tile's size");
  }
  if (wall.tiles.empty()) return makeError(file + ": no 'tile' line");
  for (const auto& t : wall.tiles) {
    if (t.col < 0 || t.row < 0 || t.col >= wall.cols || t.row >= wall.rows) {
      return makeError(file + ":" + std::to_string(t.line) + ": tile '" + t.id +
                       "' is outside the " + std::to_string(wall.cols) + " x " +
                       std::to_string(wall.rows) + " grid");
    }
  }
  return wall;
}

Result<Wall> loadWall(const std::string& path) {
  std::ifstream in(path);
  if (!in) return makeError("cannot read wall file '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  return parseWall(text.str(), path);
}

TileRect tileRect(const Wall& wall, int col, int row) {
  const Span s = span(wall, col, row);
  const auto c = asEigen(wall.centre), R = asEigen(wall.right), U = asEigen(wall.up);
  return TileRect{msg::toVec3(c + R * s.u0 + U * s.v0), msg::toVec3(c + R * s.u1 + U * s.v0),
                  msg::toVec3(c + R * s.u0 + U * s.v1)};
}

Result<TileView> tileView(const Wall& wall, int col, int row, const msg::Vec3& eye,
                          double nearPlane, double farPlane) {
  // Kooima's generalized perspective projection: the screen's frame, the eye's distance to its
  // plane, and the rectangle's edges seen from the eye, scaled to the near plane.
  const TileRect rect = tileRect(wall, col, row);
  const Eigen::Vector3d vr = asEigen(wall.right), vu = asEigen(wall.up), vn = vr.cross(vu);
  const Eigen::Vector3d pe = asEigen(eye);
  const Eigen::Vector3d va = asEigen(rect.lowerLeft) - pe, vb = asEigen(rect.lowerRight) - pe,
                        vc = asEigen(rect.upperLeft) - pe;
  const double d = -vn.dot(va);
  if (!finite(eye) || !(d > nearPlane)) {
    return makeError("the eye must be in front of the wall by more than the near plane (" +
                     std::to_string(nearPlane) + " m); it is " + std::to_string(d) + " m");
  }
  TileView view;
  view.camera.eye = eye;
  view.camera.target = msg::toVec3(pe - vn);
  view.camera.up = wall.up;
  view.camera.nearPlane = nearPlane;
  view.camera.farPlane = farPlane;
  const double k = nearPlane / d;
  view.frustum =
      Frustum{vr.dot(va) * k, vr.dot(vb) * k, vu.dot(va) * k, vu.dot(vc) * k, nearPlane, farPlane};
  // The vertical field of view the window spans at the eye, for what reads the camera alone.
  view.camera.fovYDegrees = std::atan2(view.frustum.top, nearPlane) * 180.0 / 3.14159265358979 -
                            std::atan2(view.frustum.bottom, nearPlane) * 180.0 / 3.14159265358979;
  return view;
}

double blendWeight(const Wall& wall, int col, int row, double u, double v) {
  const Span s = span(wall, col, row);
  return ramp(u, s.u0, s.u1, wall.overlapX, col == 0, col == wall.cols - 1) *
         ramp(v, s.v0, s.v1, wall.overlapY, row == wall.rows - 1, row == 0);
}

std::vector<std::uint8_t> blendMask(const Wall& wall, int col, int row) {
  if (wall.overlapX <= 0 && wall.overlapY <= 0) return {};
  const Span s = span(wall, col, row);
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(wall.pixelsX) * wall.pixelsY);
  for (int j = 0; j < wall.pixelsY; ++j) {
    const double v = s.v1 - (j + 0.5) / wall.pixelsY * wall.sizeY;
    for (int i = 0; i < wall.pixelsX; ++i) {
      const double u = s.u0 + (i + 0.5) / wall.pixelsX * wall.sizeX;
      const double w = std::pow(blendWeight(wall, col, row, u, v), 1.0 / wall.gamma);
      mask[static_cast<std::size_t>(j) * wall.pixelsX + i] =
          static_cast<std::uint8_t>(std::lround(255.0 * w));
    }
  }
  return mask;
}

}  // namespace vrflow::viewer
