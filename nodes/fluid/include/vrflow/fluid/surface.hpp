#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/fluid/settings.hpp"
#include "vrflow/message/values.hpp"

// The liquid's surface as a triangle mesh, built from its particles in one of two ways, then
// meshed by OpenVDB's volumeToMesh (quads split into triangles):
// - Density (the default): the particles' number density, splatted with a tent kernel of two
//   voxels' radius onto the voxels' corners, whose isosurface at half the density of a full
//   block of particles is the liquid's boundary (for a flat block, its face).
// - Spheres: each particle is a sphere rasterised into a narrow-band level set (OpenVDB's
//   ParticlesToLevelSet), rebuilt as a signed distance and moved inwards so that a flat block of
//   particles gives its block's faces. Slower (the benchmark), kept for comparison.
// Faces lying on the grid's walls are left out: a viewer sees the free surface, and the liquid's
// side against a wall is the wall. One thread (an own TBB arena), deterministic: the same
// particles give the same bits.

namespace vrflow::fluid {

/// How the particles become a volume to mesh (see above).
enum class SurfaceMethod { Density, Spheres };

/// How the surface is built. surfaceSettings() derives them from the fluid's settings.
struct SurfaceSettings {
  SurfaceMethod method = SurfaceMethod::Density;
  double particleSpacing = 1.0 / 64.0;  ///< of the seeded particles (m): sets the full density
  double voxelSize = 1.0 / 64.0;        ///< edge of the level set's voxels (m)
  double particleRadius = 1.0 / 32.0;   ///< radius of each particle's sphere (m), >= 1.5 voxels
  double inset = 0.75 / 32.0;           ///< how far the union of spheres is moved inwards (m)
  msg::Aabb walls{};                    ///< the grid's box: faces lying on its walls are left out
  double wallBand = 1.0 / 64.0;         ///< "on a wall": all three corners within this of its plane
};

/// The settings for a fluid: `voxelsPerCell` voxels along a cell's edge, the density method;
/// for the spheres method, spheres of twice the particle spacing (at least 1.5 voxels) moved in
/// by that radius less half a spacing (the outermost particles of a seeded block lie half a
/// spacing inside its face); walls = the grid.
SurfaceSettings surfaceSettings(const FluidSettings& fluid, int voxelsPerCell);

/// A triangle mesh: xyz floats per vertex, three vertex indices per triangle, counter-clockwise
/// seen from the air (normals point out of the liquid).
struct SurfaceMesh {
  std::vector<float> xyz;
  std::vector<std::uint32_t> indices;

  std::size_t vertexCount() const { return xyz.size() / 3; }
  std::size_t triangleCount() const { return indices.size() / 3; }
};

/// The surface of the liquid whose particles are `xyz` (three floats each). Settings that are
/// not finite and positive, or a radius under 1.5 voxels, are an error; no particles give an
/// empty mesh.
Result<SurfaceMesh> extractSurface(const std::vector<float>& xyz, const SurfaceSettings& settings);

/// One box of a split of the grid and the part of the surface in it, with its own vertex list.
struct SurfaceRegion {
  SurfaceMesh mesh;
  /// The box of its vertices, kept 1e-5 of a box inside the planes it shares with other boxes
  /// (so that a view that only touches the box does not meet it); the region's box when it
  /// holds nothing.
  msg::Aabb bounds{};
};

/// Cuts `mesh` into the counts[0] x counts[1] x counts[2] boxes of `grid` (x fastest), as the
/// module's particle regions: a triangle within one box goes to it whole; one across boxes is
/// clipped at their planes, each piece (a fan of triangles with new vertices) to its box. The
/// first and last box along an axis take what lies beyond the grid.
std::vector<SurfaceRegion> splitSurface(const SurfaceMesh& mesh, const msg::Aabb& grid,
                                        const std::array<int, 3>& counts);

/// The volume a closed mesh encloses (divergence theorem; positive for outward normals), m^3.
double enclosedVolume(const SurfaceMesh& mesh);

/// Edges not shared by exactly two triangles (0: watertight), found by vertex index.
std::vector<std::array<std::uint32_t, 2>> openEdges(const SurfaceMesh& mesh);

}  // namespace vrflow::fluid
