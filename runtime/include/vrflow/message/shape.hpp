#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/message/values.hpp"

// Collision shapes, the resource a rigid object's `shape` parameter names. Every package that
// reads rigid objects (the rigid interactor, the mass-spring/rigid interactor, the fluid, viewers)
// decodes the same bytes, so the shape travels once per receiver as a static Raw resource.
// docs/message-layout.md ("Shape resources") is the reference for the encoding.

namespace vrflow::msg {

/// What a shape is. Values are part of the encoding.
enum class ShapeKind : std::uint32_t {
  Sphere = 1,        ///< radius
  Box = 2,           ///< halfExtents
  Capsule = 3,       ///< radius, halfHeight of the cylinder part along the body's y axis
  ConvexHull = 4,    ///< vertices, and indices: the hull's triangles, outward (counter-clockwise)
  TriangleMesh = 5,  ///< vertices and indices; concave; closed when used by the fluid
};

/// A collision shape in its body frame (the frame of the rigid object's position/orientation,
/// whose origin is the centre of mass).
struct Shape {
  ShapeKind kind = ShapeKind::Sphere;
  double radius = 0.0;
  Vec3 halfExtents{};
  double halfHeight = 0.0;
  std::vector<double> vertices;        ///< xyz per vertex (ConvexHull, TriangleMesh)
  std::vector<std::uint32_t> indices;  ///< three per triangle (ConvexHull, TriangleMesh)

  static Shape sphere(double radius);
  static Shape box(const Vec3& halfExtents);
  static Shape capsule(double radius, double halfHeight);
  static Shape convexHull(std::vector<double> vertices, std::vector<std::uint32_t> triangles);
  static Shape triangleMesh(std::vector<double> vertices, std::vector<std::uint32_t> triangles);

  bool operator==(const Shape&) const = default;
};

/// Most vertices and indices a shape may hold (keeps a forged resource from asking for gigabytes).
inline constexpr std::uint32_t kMaxShapeVertices = 1u << 20;
inline constexpr std::uint32_t kMaxShapeIndices = 3u << 21;

/// Checks a shape: finite positive sizes, vertex and index counts, indices in range.
Status validateShape(const Shape& shape);

/// The bytes of a shape resource (a static Raw resource body).
std::vector<std::byte> encodeShape(const Shape& shape);
/// Reads a shape resource, rejecting truncated, oversized or invalid bytes.
Result<Shape> decodeShape(std::span<const std::byte> bytes);

/// The shape's bounding box in its body frame.
Aabb localBounds(const Shape& shape);
/// The world bounding box of the shape placed at `position` with unit quaternion `orientation`.
Aabb worldBounds(const Shape& shape, const Vec3& position, const Quat& orientation);

/// Volume, and the inertia tensor (row-major, about the body origin) of the shape filled with
/// uniform density so that its mass is `mass`. Exact for the primitives; for hulls and meshes
/// (closed, outward triangles) from the signed tetrahedra of each triangle with the origin.
struct MassProperties {
  double volume = 0.0;
  Mat3 inertia{};
};
MassProperties massProperties(const Shape& shape, double mass);

/// Signed distance from a body-frame point to the surface (negative inside), and the outward
/// unit normal of the nearest surface point. Exact for sphere, box and capsule; for a hull, exact
/// inside and at faces, the largest face-plane distance outside (a lower bound near edges); for a
/// triangle mesh, the distance to the nearest triangle signed by that triangle's normal.
struct SurfaceDistance {
  double distance = 0.0;
  Vec3 normal{};
};
SurfaceDistance signedDistance(const Shape& shape, const Vec3& point);

/// A triangle mesh for drawing the shape: xyz per vertex and outward counter-clockwise triangles.
/// `segments` (at least 4) sets how finely spheres and capsules are tessellated.
struct RenderMesh {
  std::vector<float> xyz;
  std::vector<std::uint32_t> indices;
};
RenderMesh renderMesh(const Shape& shape, int segments = 16);

/// Quaternion helpers shared by the packages (x, y, z, w order, unit length).
Vec3 rotate(const Quat& q, const Vec3& v);
Vec3 rotateInverse(const Quat& q, const Vec3& v);

}  // namespace vrflow::msg
