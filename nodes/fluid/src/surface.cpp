// The surface's level set and mesh through OpenVDB: the only file that includes its headers
// (they are heavy to compile).
#include "vrflow/fluid/surface.hpp"

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/task_arena.h>

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

}  // namespace

Result<SurfaceMesh> extractSurface(const std::vector<float>& xyz, const SurfaceSettings& s) {
  if (!positive(s.voxelSize) || !positive(s.particleRadius) || !std::isfinite(s.inset) ||
      s.inset < 0.0 || !std::isfinite(s.wallBand) || s.wallBand < 0.0) {
    return makeError(
        "fluid surface: voxel size, particle radius, inset and wall band must be "
        "finite, the first two positive");
  }
  if (s.particleRadius < 1.5 * s.voxelSize) {
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

  // The rebuilt level set's inner band reaches the inset and two voxels beyond.
  const double inBand = s.inset / s.voxelSize + 2.0;
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  // OpenVDB's tools run on TBB; one thread here (solvers own no threads, and the order of the
  // output must not depend on scheduling).
  tbb::task_arena arena(1);
  arena.execute([&] {
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

  mesh.xyz.reserve(points.size() * 3);
  for (const auto& p : points) mesh.xyz.insert(mesh.xyz.end(), {p[0], p[1], p[2]});
  // volumeToMesh's polygons are clockwise seen from outside: each is emitted reversed.
  const auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (onWall(s, points[a], points[b], points[c])) return;
    mesh.indices.insert(mesh.indices.end(), {a, c, b});
  };
  for (const auto& t : triangles) add(t[0], t[1], t[2]);
  for (const auto& q : quads) {
    add(q[0], q[1], q[2]);
    add(q[0], q[2], q[3]);
  }
  return mesh;
}

}  // namespace vrflow::fluid
