#pragma once

#include <cstdint>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/rigid/body.hpp"

// Closed triangle meshes as the bodies of moving (dynamic) rigid bodies. A dynamic mesh collides
// with its own, possibly concave, surface (Bullet's GImpact in the contact solver), and its mass
// and inertia come from the volume it encloses (msg::massProperties: the divergence theorem over
// its triangles), so it must enclose one: every edge shared by exactly two triangles that run
// along it in opposite directions (closed and consistently wound), no zero-area triangle, a
// non-zero volume. Kinematic meshes may be open (a ground, a ramp).

namespace vrflow::rigid {

/// Checks that a triangle mesh is closed, consistently wound, has no degenerate triangle and
/// encloses a volume; the error says which edge or triangle is at fault.
Status checkClosedMesh(const msg::Shape& mesh);

/// The centroid of the volume enclosed by closed triangles (signed tetrahedra from the points'
/// mean, so that the sum stays well conditioned far from the origin). Either winding works.
Result<Eigen::Vector3d> volumeCentroid(const std::vector<Eigen::Vector3d>& vertices,
                                       const std::vector<std::uint32_t>& triangles);

/// A closed mesh moved so that its volume centroid is the origin (the body frame's convention);
/// the shift is returned in `centroid` when given. Checks the mesh first (checkClosedMesh).
Result<msg::Shape> centredMesh(const msg::Shape& mesh, Vec3* centroid = nullptr);

/// Builds closed triangle meshes from planar convex quads, each given with its outward normal so
/// that its two triangles are wound outward whatever the corners' order (generators and tests).
class QuadMeshBuilder {
 public:
  /// Adds a vertex (no merging) and returns its index.
  std::uint32_t vertex(const Vec3& p);
  /// Adds the quad a, b, c, d (corners in cyclic order) as two triangles facing `outward`.
  void quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d,
            const Vec3& outward);
  /// The mesh built so far.
  msg::Shape shape() const;

 private:
  std::vector<double> vertices_;
  std::vector<std::uint32_t> indices_;
};

/// An open-topped box, the bowl of the tests, examples and benchmark: outer half width
/// `halfWidth` (x and z), height `height` (from y = 0), walls and floor `wall` thick; a closed
/// surface of 28 triangles whose cavity is [-(halfWidth - wall), halfWidth - wall] in x and z,
/// [wall, height] in y. Not centred: centredMesh moves it to its centroid.
msg::Shape bowlMesh(double halfWidth, double height, double wall);

}  // namespace vrflow::rigid
