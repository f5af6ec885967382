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

std::vector<SurfaceRegion> splitSurface(const SurfaceMesh& mesh, const msg::Aabb& grid,
                                        const std::array<int, 3>& counts) {
  const std::size_t regions = static_cast<std::size_t>(counts[0] * counts[1] * counts[2]);
  std::vector<SurfaceRegion> out(regions);
  // Per region: the index there of each vertex of `mesh` it holds.
  std::vector<std::map<std::uint32_t, std::uint32_t>> local(regions);
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    std::size_t region = 0, stride = 1;
    for (std::size_t a = 0; a < 3; ++a) {
      double centroid = 0.0;
      for (std::size_t c = 0; c < 3; ++c) centroid += mesh.xyz[3 * mesh.indices[t + c] + a];
      centroid /= 3.0;
      const double f = (centroid - grid.min[a]) / (grid.max[a] - grid.min[a]);
      const int k = std::clamp(static_cast<int>(std::floor(f * counts[a])), 0, counts[a] - 1);
      region += static_cast<std::size_t>(k) * stride;
      stride *= static_cast<std::size_t>(counts[a]);
    }
    auto& part = out[region].mesh;
    for (std::size_t c = 0; c < 3; ++c) {
      const std::uint32_t global = mesh.indices[t + c];
      const auto [it, added] =
          local[region].try_emplace(global, static_cast<std::uint32_t>(part.vertexCount()));
      if (added) {
        part.xyz.insert(part.xyz.end(), mesh.xyz.begin() + 3 * global,
                        mesh.xyz.begin() + 3 * global + 3);
      }
      part.indices.push_back(it->second);
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
        const double step = (grid.max[a] - grid.min[a]) / counts[a];
        region.bounds.min[a] = grid.min[a] + step * static_cast<double>(cell[a]);
        region.bounds.max[a] = static_cast<int>(cell[a]) + 1 == counts[a]
                                   ? grid.max[a]
                                   : grid.min[a] + step * static_cast<double>(cell[a] + 1);
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
