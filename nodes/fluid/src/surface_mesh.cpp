// The surface's settings from the fluid's, and what is done with a surface mesh once built:
// split into regions, its enclosed volume, its open edges.
#include <algorithm>
#include <cmath>
#include <map>

#include "vrflow/fluid/surface.hpp"

namespace vrflow::fluid {

SurfaceSettings surfaceSettings(const FluidSettings& fluid, int voxelsPerCell) {
  SurfaceSettings s;
  const double h = fluid.cellSize;
  const double spacing = h / std::cbrt(static_cast<double>(fluid.particlesPerCell));
  s.particleSpacing = spacing;
  s.voxelSize = h / std::max(voxelsPerCell, 1);
  s.particleRadius = std::max(2.0 * spacing, 1.5 * s.voxelSize);
  s.inset = s.particleRadius - 0.5 * spacing;
  s.walls.min = fluid.origin;
  s.walls.max = {fluid.origin[0] + h * fluid.nx, fluid.origin[1] + h * fluid.ny,
                 fluid.origin[2] + h * fluid.nz};
  s.wallBand = s.voxelSize;
  return s;
}

namespace {

using Point = std::array<double, 3>;
/// A cut's point on an edge of the mesh: the edge's vertices (lower first), the axis and the
/// index of the plane; the same for the two triangles that share the edge.
using CutKey = std::array<std::int64_t, 4>;

/// A point of a clipped triangle: a vertex of the mesh (`vertex` >= 0), a cut of one of its
/// edges (`shared`: `key` names it), or a point of neither (a second cut at a box's corner).
struct ClipPoint {
  Point p{};
  std::int64_t vertex = -1;
  bool shared = false;
  CutKey key{};
};

// The part of polygon `in` on one side of plane `plane` (x[axis] = value; below: x <= value),
// Sutherland-Hodgman; the points kept are `in`'s, the new ones `inset` inside the plane (so
// that the piece's bounds do not touch the neighbouring box: boxes meet when they touch). A cut
// of an edge between two mesh vertices is computed from its lower vertex, so that both triangles
// of the edge get the same point.
std::vector<ClipPoint> clipPolygon(const std::vector<ClipPoint>& in, std::size_t axis, int plane,
                                   double value, bool below, double inset) {
  std::vector<ClipPoint> out;
  const auto inside = [&](const ClipPoint& q) {
    return below ? q.p[axis] <= value : q.p[axis] >= value;
  };
  for (std::size_t i = 0; i < in.size(); ++i) {
    const ClipPoint& a = in[i];
    const ClipPoint& b = in[(i + 1) % in.size()];
    if (inside(a)) out.push_back(a);
    if (inside(a) == inside(b)) continue;
    const bool edge = a.vertex >= 0 && b.vertex >= 0;
    const ClipPoint& from = edge && b.vertex < a.vertex ? b : a;
    const ClipPoint& to = &from == &a ? b : a;
    const double t = (value - from.p[axis]) / (to.p[axis] - from.p[axis]);
    ClipPoint cut;
    for (std::size_t c = 0; c < 3; ++c) cut.p[c] = from.p[c] + t * (to.p[c] - from.p[c]);
    cut.p[axis] = below ? value - inset : value + inset;
    if (edge) {
      cut.shared = true;
      cut.key = {from.vertex, to.vertex, static_cast<std::int64_t>(axis), plane};
    }
    out.push_back(cut);
  }
  return out;
}

// Twice the area of a polygon (a fan from its first point).
double doubleArea(const std::vector<ClipPoint>& poly) {
  double sum = 0.0;
  for (std::size_t i = 1; i + 1 < poly.size(); ++i) {
    Point u, v;
    for (std::size_t c = 0; c < 3; ++c) {
      u[c] = poly[i].p[c] - poly[0].p[c];
      v[c] = poly[i + 1].p[c] - poly[0].p[c];
    }
    sum +=
        std::sqrt(std::pow(u[1] * v[2] - u[2] * v[1], 2) + std::pow(u[2] * v[0] - u[0] * v[2], 2) +
                  std::pow(u[0] * v[1] - u[1] * v[0], 2));
  }
  return sum;
}

}  // namespace

std::vector<SurfaceRegion> splitSurface(const SurfaceMesh& mesh, const msg::Aabb& grid,
                                        const std::array<int, 3>& counts) {
  const std::size_t regions = static_cast<std::size_t>(counts[0] * counts[1] * counts[2]);
  std::vector<SurfaceRegion> out(regions);
  std::array<double, 3> step{};
  for (std::size_t a = 0; a < 3; ++a) step[a] = (grid.max[a] - grid.min[a]) / counts[a];
  // The box along `a` holding coordinate v (the first and last take what lies beyond the grid).
  const auto boxOf = [&](std::size_t a, double v) {
    return std::clamp(static_cast<int>(std::floor((v - grid.min[a]) / step[a])), 0, counts[a] - 1);
  };
  const auto regionOf = [&](const std::array<int, 3>& box) {
    return static_cast<std::size_t>(box[0] + counts[0] * (box[1] + counts[1] * box[2]));
  };
  // Per region: the index there of each vertex of `mesh` it holds, and of each cut of an edge.
  std::vector<std::map<std::uint32_t, std::uint32_t>> local(regions);
  std::vector<std::map<CutKey, std::uint32_t>> cuts(regions);
  const auto addVertex = [&](std::size_t region, std::uint32_t global) {
    auto& part = out[region].mesh;
    const auto [it, added] =
        local[region].try_emplace(global, static_cast<std::uint32_t>(part.vertexCount()));
    if (added) {
      part.xyz.insert(part.xyz.end(), mesh.xyz.begin() + 3 * global,
                      mesh.xyz.begin() + 3 * global + 3);
    }
    return it->second;
  };
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    std::array<int, 3> low{}, high{};
    for (std::size_t a = 0; a < 3; ++a) {
      low[a] = counts[a];
      high[a] = -1;
      for (std::size_t c = 0; c < 3; ++c) {
        const int k = boxOf(a, mesh.xyz[3 * mesh.indices[t + c] + a]);
        low[a] = std::min(low[a], k);
        high[a] = std::max(high[a], k);
      }
    }
    if (low == high) {
      // Inside one box: the triangle as it is, its vertices shared with the box's others.
      const std::size_t region = regionOf(low);
      for (std::size_t c = 0; c < 3; ++c) {
        out[region].mesh.indices.push_back(addVertex(region, mesh.indices[t + c]));
      }
      continue;
    }
    // Across boxes: cut at their planes, so that each box holds only what lies in it and its
    // bounds stay inside it (a route then sends it only to the views that meet the box).
    std::vector<ClipPoint> triangle;
    for (std::size_t c = 0; c < 3; ++c) {
      const float* v = &mesh.xyz[3 * mesh.indices[t + c]];
      triangle.push_back({{v[0], v[1], v[2]}, mesh.indices[t + c], false, {}});
    }
    const double whole = doubleArea(triangle);
    std::array<int, 3> box{};
    for (box[2] = low[2]; box[2] <= high[2]; ++box[2]) {
      for (box[1] = low[1]; box[1] <= high[1]; ++box[1]) {
        for (box[0] = low[0]; box[0] <= high[0]; ++box[0]) {
          std::vector<ClipPoint> piece = triangle;
          for (std::size_t a = 0; a < 3 && piece.size() >= 3; ++a) {
            const double inset = 1e-5 * step[a];
            if (box[a] > 0) {
              piece = clipPolygon(piece, a, box[a], grid.min[a] + step[a] * box[a], false, inset);
            }
            if (box[a] + 1 < counts[a] && piece.size() >= 3) {
              piece = clipPolygon(piece, a, box[a] + 1, grid.min[a] + step[a] * (box[a] + 1), true,
                                  inset);
            }
          }
          // Pieces of no area (a corner or an edge on a plane) are left out.
          if (piece.size() < 3 || doubleArea(piece) <= 1e-9 * whole) continue;
          const std::size_t region = regionOf(box);
          auto& part = out[region].mesh;
          std::vector<std::uint32_t> corners;
          for (const ClipPoint& q : piece) {
            if (q.vertex >= 0) {
              corners.push_back(addVertex(region, static_cast<std::uint32_t>(q.vertex)));
              continue;
            }
            const auto next = static_cast<std::uint32_t>(part.vertexCount());
            const auto [it, added] = q.shared ? cuts[region].try_emplace(q.key, next)
                                              : std::pair{cuts[region].end(), true};
            if (added) {
              for (std::size_t c = 0; c < 3; ++c) part.xyz.push_back(static_cast<float>(q.p[c]));
            }
            corners.push_back(added ? next : it->second);
          }
          for (std::size_t i = 1; i + 1 < corners.size(); ++i) {
            part.indices.insert(part.indices.end(), {corners[0], corners[i], corners[i + 1]});
          }
        }
      }
    }
  }
  for (std::size_t r = 0; r < regions; ++r) {
    auto& region = out[r];
    if (region.mesh.xyz.empty()) {
      const std::array<std::size_t, 3> cell{
          r % static_cast<std::size_t>(counts[0]),
          (r / static_cast<std::size_t>(counts[0])) % static_cast<std::size_t>(counts[1]),
          r / static_cast<std::size_t>(counts[0] * counts[1])};
      for (std::size_t a = 0; a < 3; ++a) {
        region.bounds.min[a] = grid.min[a] + step[a] * static_cast<double>(cell[a]);
        region.bounds.max[a] = static_cast<int>(cell[a]) + 1 == counts[a]
                                   ? grid.max[a]
                                   : grid.min[a] + step[a] * static_cast<double>(cell[a] + 1);
      }
      continue;
    }
    for (std::size_t a = 0; a < 3; ++a) {
      region.bounds.min[a] = region.bounds.max[a] = region.mesh.xyz[a];
    }
    for (std::size_t i = 0; i < region.mesh.xyz.size(); ++i) {
      const double v = region.mesh.xyz[i];
      region.bounds.min[i % 3] = std::min(region.bounds.min[i % 3], v);
      region.bounds.max[i % 3] = std::max(region.bounds.max[i % 3], v);
    }
    // A vertex of an uncut triangle may lie on a plane between boxes (the voxels' corners fall
    // there): the bounds stop just inside it, since the neighbour holds nothing of this box.
    const std::array<int, 3> cell{
        static_cast<int>(r % static_cast<std::size_t>(counts[0])),
        static_cast<int>((r / static_cast<std::size_t>(counts[0])) %
                         static_cast<std::size_t>(counts[1])),
        static_cast<int>(r / static_cast<std::size_t>(counts[0] * counts[1]))};
    for (std::size_t a = 0; a < 3; ++a) {
      const double inset = 1e-5 * step[a];
      if (cell[a] > 0) {
        region.bounds.min[a] =
            std::max(region.bounds.min[a], grid.min[a] + step[a] * cell[a] + inset);
      }
      if (cell[a] + 1 < counts[a]) {
        region.bounds.max[a] =
            std::min(region.bounds.max[a], grid.min[a] + step[a] * (cell[a] + 1) - inset);
      }
    }
  }
  return out;
}

double enclosedVolume(const SurfaceMesh& mesh) {
  double six = 0.0;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const float* a = &mesh.xyz[3 * mesh.indices[t]];
    const float* b = &mesh.xyz[3 * mesh.indices[t + 1]];
    const float* c = &mesh.xyz[3 * mesh.indices[t + 2]];
    // a . (b x c): six times the signed volume of the tetrahedron (origin, a, b, c).
    six += a[0] * (static_cast<double>(b[1]) * c[2] - static_cast<double>(b[2]) * c[1]) +
           a[1] * (static_cast<double>(b[2]) * c[0] - static_cast<double>(b[0]) * c[2]) +
           a[2] * (static_cast<double>(b[0]) * c[1] - static_cast<double>(b[1]) * c[0]);
  }
  return six / 6.0;
}

std::vector<std::array<std::uint32_t, 2>> openEdges(const SurfaceMesh& mesh) {
  std::map<std::array<std::uint32_t, 2>, int> uses;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    for (std::size_t e = 0; e < 3; ++e) {
      const std::uint32_t a = mesh.indices[t + e], b = mesh.indices[t + (e + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  }
  std::vector<std::array<std::uint32_t, 2>> open;
  for (const auto& [edge, count] : uses) {
    if (count != 2) open.push_back(edge);
  }
  return open;
}

}  // namespace vrflow::fluid
