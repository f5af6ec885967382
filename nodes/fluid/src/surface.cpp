// The surface's level set and mesh through OpenVDB: the only file that includes its headers
// (they are heavy to compile).
#include "vrflow/fluid/surface.hpp"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>

namespace vrflow::fluid {
namespace {

// The particle list ParticlesToLevelSet reads: xyz floats, one radius for all.
class ParticleList {
 public:
  using PosType = openvdb::Vec3R;
  ParticleList(const std::vector<float>& xyz, double radius) : xyz_(xyz), radius_(radius) {}
  std::size_t size() const { return xyz_.size() / 3; }
  void getPos(std::size_t n, openvdb::Vec3R& p) const {
    p = openvdb::Vec3R(xyz_[3 * n], xyz_[3 * n + 1], xyz_[3 * n + 2]);
  }
  void getPosRad(std::size_t n, openvdb::Vec3R& p, openvdb::Real& r) const {
    getPos(n, p);
    r = radius_;
  }

 private:
  const std::vector<float>& xyz_;
  double radius_;
};

bool positive(double v) {
  return std::isfinite(v) && v > 0.0;
}

// True when the three corners lie on (within `band` of, or beyond) one wall of `walls`.
bool onWall(const SurfaceSettings& s, const openvdb::Vec3s& a, const openvdb::Vec3s& b,
            const openvdb::Vec3s& c) {
  for (int axis = 0; axis < 3; ++axis) {
    const auto k = static_cast<std::size_t>(axis);
    const double low = s.walls.min[k] + s.wallBand, high = s.walls.max[k] - s.wallBand;
    if (a[axis] <= low && b[axis] <= low && c[axis] <= low) return true;
    if (a[axis] >= high && b[axis] >= high && c[axis] >= high) return true;
  }
  return false;
}

// phi = 1/2 - density / full density at the voxels' corners (negative inside, as a level set),
// over the particles' box widened by the kernel; 1/2 (outside) elsewhere. The kernel's radius
// is two particle spacings (a cell for 8 particles per cell), whatever the voxels.
openvdb::FloatGrid::Ptr densityGrid(const std::vector<float>& xyz, const SurfaceSettings& s) {
  const double dx = s.voxelSize;
  const int kernel = std::max(1, static_cast<int>(std::lround(2.0 * s.particleSpacing / dx)));
  const auto taps = static_cast<std::size_t>(2 * kernel);
  std::array<double, 3> low{}, high{};
  for (std::size_t a = 0; a < 3; ++a) low[a] = high[a] = xyz[a];
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    low[i % 3] = std::min(low[i % 3], static_cast<double>(xyz[i]));
    high[i % 3] = std::max(high[i % 3], static_cast<double>(xyz[i]));
  }
  std::array<double, 3> origin{};
  std::array<std::size_t, 3> size{};
  for (std::size_t a = 0; a < 3; ++a) {
    origin[a] = std::floor(low[a] / dx) * dx - (kernel + 1) * dx;
    size[a] = static_cast<std::size_t>(std::ceil((high[a] - origin[a]) / dx)) +
              static_cast<std::size_t>(kernel) + 2;
  }
  const openvdb::CoordBBox box(
      openvdb::Coord(0, 0, 0),
      openvdb::Coord(static_cast<int>(size[0]) - 1, static_cast<int>(size[1]) - 1,
                     static_cast<int>(size[2]) - 1));
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, 0.0f);
  // A particle weighs (1 - |d| / R) per axis on the corners within R voxels: inside a full
  // block, the weights sum to (R dx / spacing)^3.
  const double full = std::pow(kernel * dx / s.particleSpacing, 3.0);
  float* data = dense.data();
  std::array<std::vector<double>, 3> w;
  for (auto& axis : w) axis.resize(taps);
  for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) {
    std::array<std::size_t, 3> base{};
    for (std::size_t a = 0; a < 3; ++a) {
      const double g = (xyz[i + a] - origin[a]) / dx;
      const int first = static_cast<int>(std::floor(g)) - kernel + 1;
      base[a] = static_cast<std::size_t>(first);
      for (std::size_t n = 0; n < taps; ++n) {
        w[a][n] = std::max(0.0, 1.0 - std::abs(g - (first + static_cast<int>(n))) / kernel);
      }
    }
    for (std::size_t k = 0; k < taps; ++k) {
      for (std::size_t j = 0; j < taps; ++j) {
        const double wjk = w[1][j] * w[2][k] / full;
        // LayoutXYZ: x fastest.
        float* row = data + base[0] + size[0] * ((base[1] + j) + size[1] * (base[2] + k));
        for (std::size_t n = 0; n < taps; ++n) row[n] += static_cast<float>(w[0][n] * wjk);
      }
    }
  }
  for (std::size_t i = 0; i < dense.valueCount(); ++i) data[i] = 0.5f - data[i];
  auto grid = openvdb::FloatGrid::create(0.5f);
  auto transform = openvdb::math::Transform::createLinearTransform(dx);
  transform->postTranslate(openvdb::Vec3d(origin[0], origin[1], origin[2]));
  grid->setTransform(transform);
  openvdb::tools::copyFromDense(dense, *grid, 0.0f);
  return grid;
}

}  // namespace

Result<SurfaceMesh> extractSurface(const std::vector<float>& xyz, const SurfaceSettings& s) {
  if (!positive(s.voxelSize) || !positive(s.particleSpacing) || !positive(s.particleRadius) ||
      !std::isfinite(s.inset) || s.inset < 0.0 || !std::isfinite(s.wallBand) || s.wallBand < 0.0) {
    return makeError(
        "fluid surface: voxel size, particle spacing and radius, inset and wall band "
        "must be finite, the first three positive");
  }
  if (s.method == SurfaceMethod::Spheres && s.particleRadius < 1.5 * s.voxelSize) {
    return makeError("fluid surface: particle radius " + std::to_string(s.particleRadius) +
                     " m is under 1.5 voxels of " + std::to_string(s.voxelSize) + " m");
  }
  SurfaceMesh mesh;
  if (xyz.size() < 3) return mesh;
  for (const float v : xyz) {
    if (!std::isfinite(v)) return makeError("fluid surface: a particle position is not finite");
  }
  static std::once_flag initialised;
  std::call_once(initialised, [] { openvdb::initialize(); });

  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  // OpenVDB's tools run on TBB; one thread here (solvers own no threads, and the order of the
  // output must not depend on scheduling).
  tbb::task_arena arena(1);
  arena.execute([&] {
    if (s.method == SurfaceMethod::Density) {
      openvdb::tools::volumeToMesh(*densityGrid(xyz, s), points, triangles, quads, 0.0, 0.0, true);
      return;
    }
    // The rebuilt level set's inner band reaches the inset and two voxels beyond.
    const double inBand = s.inset / s.voxelSize + 2.0;
    auto spheres = openvdb::createLevelSet<openvdb::FloatGrid>(s.voxelSize, 3.0);
    openvdb::tools::ParticlesToLevelSet<openvdb::FloatGrid> raster(*spheres);
    raster.setGrainSize(0);
    raster.rasterizeSpheres(ParticleList(xyz, s.particleRadius));
    raster.finalize(true);
    // The spheres' union holds each sphere's distance, not the distance to the union's surface
    // (between particles it never falls below -(radius - their gap)): rebuilt as a true signed
    // distance deep enough inside, its isosurface -inset is the union moved inwards by inset.
    const auto grid =
        openvdb::tools::levelSetRebuild(*spheres, 0.0f, 2.0f, static_cast<float>(inBand));
    openvdb::tools::volumeToMesh(*grid, points, triangles, quads, -s.inset, 0.0, true);
  });

  // Only the vertices of the triangles kept, in the order they are first used.
  std::vector<std::uint32_t> index(points.size(), UINT32_MAX);
  const auto vertex = [&](std::uint32_t v) {
    if (index[v] == UINT32_MAX) {
      index[v] = static_cast<std::uint32_t>(mesh.xyz.size() / 3);
      mesh.xyz.insert(mesh.xyz.end(), {points[v][0], points[v][1], points[v][2]});
    }
    return index[v];
  };
  // volumeToMesh's polygons are counter-clockwise seen from outside for a plain scalar grid
  // (the density) and clockwise for a level set (the spheres'): those are emitted reversed.
  const bool reverse = s.method == SurfaceMethod::Spheres;
  const auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (onWall(s, points[a], points[b], points[c])) return;
    const std::uint32_t first = vertex(a);
    const std::uint32_t second = vertex(reverse ? c : b);
    const std::uint32_t third = vertex(reverse ? b : c);
    mesh.indices.insert(mesh.indices.end(), {first, second, third});
  };
  for (const auto& t : triangles) add(t[0], t[1], t[2]);
  for (const auto& q : quads) {
    add(q[0], q[1], q[2]);
    add(q[0], q[2], q[3]);
  }
  return mesh;
}

}  // namespace vrflow::fluid
