#include "vrflow/message/shape.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <string>
#include <utility>

#include "vrflow/message/eigen.hpp"

namespace vrflow::msg {
namespace {

// 'S' 'H' 'P' '1' read as a little-endian u32.
constexpr std::uint32_t kShapeMagic = 0x31504853u;
constexpr std::size_t kShapeHeaderSize = 56;

using Eigen::Vector3d;

/// The unit vector along a, or the fallback for a (near) zero vector.
Vector3d normalized(const Vector3d& a, const Vector3d& fallback) {
  const double len = a.norm();
  return len > 1e-300 ? Vector3d(a * (1.0 / len)) : fallback;
}

Vector3d vertex(const Shape& shape, std::uint32_t i) {
  return asVector3(&shape.vertices[3 * i]);
}

bool finitePositive(double v) {
  return std::isfinite(v) && v > 0.0;
}

template <typename T>
void put(std::vector<std::byte>& out, std::size_t offset, const T& value) {
  std::memcpy(out.data() + offset, &value, sizeof(T));
}
template <typename T>
T get(std::span<const std::byte> in, std::size_t offset) {
  T value;
  std::memcpy(&value, in.data() + offset, sizeof(T));
  return value;
}

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Vector3d closestOnTriangle(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                           const Vector3d& c) {
  const Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const double denom = 1.0 / (va + vb + vc);
  return a + (ab * (vb * denom) + ac * (vc * denom));
}

// A UV sphere of radius r; with lift > 0 its upper half moves up and its lower half down by
// lift along y, joined by a cylinder band: a capsule.
RenderMesh roundMesh(double r, double lift, int segments) {
  RenderMesh mesh;
  const int slices = std::max(4, segments);
  const int half = std::max(1, segments / 4);  // stacks per hemisphere
  // Rings from the top pole to the bottom one; the equator appears twice for a capsule.
  std::vector<std::pair<double, double>> rings;  // (y, ring radius)
  for (int i = 0; i <= half; ++i) {
    const double theta = 0.5 * std::numbers::pi * i / half;
    rings.emplace_back(r * std::cos(theta) + lift, r * std::sin(theta));
  }
  for (int i = lift > 0.0 ? 0 : 1; i <= half; ++i) {
    const double theta = 0.5 * std::numbers::pi * (1.0 + static_cast<double>(i) / half);
    rings.emplace_back(r * std::cos(theta) - lift, r * std::sin(theta));
  }
  for (const auto& [y, ring] : rings) {
    for (int j = 0; j <= slices; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / slices;
      mesh.xyz.push_back(static_cast<float>(ring * std::sin(phi)));
      mesh.xyz.push_back(static_cast<float>(y));
      mesh.xyz.push_back(static_cast<float>(ring * std::cos(phi)));
    }
  }
  const auto at = [slices](std::size_t i, int j) {
    return static_cast<std::uint32_t>(i * static_cast<std::size_t>(slices + 1) +
                                      static_cast<std::size_t>(j));
  };
  for (std::size_t i = 0; i + 1 < rings.size(); ++i) {
    for (int j = 0; j < slices; ++j) {
      const std::uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      mesh.indices.insert(mesh.indices.end(), {a, b, c, a, c, d});
    }
  }
  return mesh;
}

RenderMesh boxMesh(const Vec3& h) {
  RenderMesh mesh;
  // One quad per face with its own vertices, so flat shading needs no extra work.
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign = -1; sign <= 1; sign += 2) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const std::uint32_t base = static_cast<std::uint32_t>(mesh.xyz.size() / 3);
      const double corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (const auto& corner : corners) {
        Vec3 p{};
        p[axis] = sign * h[axis];
        p[u] = corner[0] * h[u];
        p[v] = corner[1] * h[v];
        for (double c : p) mesh.xyz.push_back(static_cast<float>(c));
      }
      if (sign > 0) {
        mesh.indices.insert(mesh.indices.end(),
                            {base, base + 1, base + 2, base, base + 2, base + 3});
      } else {
        mesh.indices.insert(mesh.indices.end(),
                            {base, base + 2, base + 1, base, base + 3, base + 2});
      }
    }
  }
  return mesh;
}

// A shape made of vertices and the triangles over them (a convex hull or a triangle mesh).
Shape trianglesShape(ShapeKind kind, std::vector<double> vertices,
                     std::vector<std::uint32_t> triangles) {
  Shape s;
  s.kind = kind;
  s.vertices = std::move(vertices);
  s.indices = std::move(triangles);
  return s;
}

}  // namespace

Shape Shape::sphere(double radius) {
  Shape s;
  s.kind = ShapeKind::Sphere;
  s.radius = radius;
  return s;
}

Shape Shape::box(const Vec3& halfExtents) {
  Shape s;
  s.kind = ShapeKind::Box;
  s.halfExtents = halfExtents;
  return s;
}

Shape Shape::capsule(double radius, double halfHeight) {
  Shape s;
  s.kind = ShapeKind::Capsule;
  s.radius = radius;
  s.halfHeight = halfHeight;
  return s;
}

Shape Shape::convexHull(std::vector<double> vertices, std::vector<std::uint32_t> triangles) {
  return trianglesShape(ShapeKind::ConvexHull, std::move(vertices), std::move(triangles));
}

Shape Shape::triangleMesh(std::vector<double> vertices, std::vector<std::uint32_t> triangles) {
  return trianglesShape(ShapeKind::TriangleMesh, std::move(vertices), std::move(triangles));
}

Status validateShape(const Shape& shape) {
  switch (shape.kind) {
    case ShapeKind::Sphere:
      if (!finitePositive(shape.radius)) return makeError("sphere radius must be finite and > 0");
      return {};
    case ShapeKind::Box:
      for (double h : shape.halfExtents) {
        if (!finitePositive(h)) return makeError("box half extents must be finite and > 0");
      }
      return {};
    case ShapeKind::Capsule:
      if (!finitePositive(shape.radius)) return makeError("capsule radius must be finite and > 0");
      if (!std::isfinite(shape.halfHeight) || shape.halfHeight < 0.0) {
        return makeError("capsule half height must be finite and >= 0");
      }
      return {};
    case ShapeKind::ConvexHull:
    case ShapeKind::TriangleMesh: {
      const char* what = shape.kind == ShapeKind::ConvexHull ? "convex hull" : "triangle mesh";
      if (shape.vertices.size() % 3 != 0) {
        return makeError(std::string(what) + ": vertices must be xyz triples");
      }
      const std::size_t vertexCount = shape.vertices.size() / 3;
      const std::size_t minVertices = shape.kind == ShapeKind::ConvexHull ? 4 : 3;
      if (vertexCount < minVertices || vertexCount > kMaxShapeVertices) {
        return makeError(std::string(what) + ": " + std::to_string(vertexCount) +
                         " vertices, expected " + std::to_string(minVertices) + " to " +
                         std::to_string(kMaxShapeVertices));
      }
      if (shape.indices.empty() || shape.indices.size() % 3 != 0 ||
          shape.indices.size() > kMaxShapeIndices) {
        return makeError(std::string(what) + ": indices must be a non-empty list of triangles");
      }
      for (double v : shape.vertices) {
        if (!std::isfinite(v)) return makeError(std::string(what) + ": a vertex is not finite");
      }
      for (std::uint32_t i : shape.indices) {
        if (i >= vertexCount) {
          return makeError(std::string(what) + ": index " + std::to_string(i) + " out of range (" +
                           std::to_string(vertexCount) + " vertices)");
        }
      }
      return {};
    }
  }
  return makeError("unknown shape kind " + std::to_string(static_cast<std::uint32_t>(shape.kind)));
}

std::vector<std::byte> encodeShape(const Shape& shape) {
  const auto vertexCount = static_cast<std::uint32_t>(shape.vertices.size() / 3);
  const auto indexCount = static_cast<std::uint32_t>(shape.indices.size());
  const std::size_t size = kShapeHeaderSize + 24u * vertexCount + 4u * indexCount;
  std::vector<std::byte> out((size + 7u) & ~std::size_t{7}, std::byte{0});
  put(out, 0, kShapeMagic);
  put(out, 4, static_cast<std::uint32_t>(shape.kind));
  put(out, 8, shape.radius);
  for (std::size_t i = 0; i < 3; ++i) put(out, 16 + 8 * i, shape.halfExtents[i]);
  put(out, 40, shape.halfHeight);
  put(out, 48, vertexCount);
  put(out, 52, indexCount);
  if (vertexCount > 0) {
    std::memcpy(out.data() + kShapeHeaderSize, shape.vertices.data(), 24u * vertexCount);
  }
  if (indexCount > 0) {
    std::memcpy(out.data() + kShapeHeaderSize + 24u * vertexCount, shape.indices.data(),
                4u * indexCount);
  }
  return out;
}

Result<Shape> decodeShape(std::span<const std::byte> bytes) {
  if (bytes.size() < kShapeHeaderSize) {
    return makeError("shape resource truncated: " + std::to_string(bytes.size()) + " bytes");
  }
  if (get<std::uint32_t>(bytes, 0) != kShapeMagic) return makeError("not a shape resource");
  Shape shape;
  const auto kind = get<std::uint32_t>(bytes, 4);
  if (kind < 1 || kind > 5) return makeError("unknown shape kind " + std::to_string(kind));
  shape.kind = static_cast<ShapeKind>(kind);
  shape.radius = get<double>(bytes, 8);
  for (std::size_t i = 0; i < 3; ++i) shape.halfExtents[i] = get<double>(bytes, 16 + 8 * i);
  shape.halfHeight = get<double>(bytes, 40);
  const auto vertexCount = get<std::uint32_t>(bytes, 48);
  const auto indexCount = get<std::uint32_t>(bytes, 52);
  if (vertexCount > kMaxShapeVertices || indexCount > kMaxShapeIndices) {
    return makeError("shape resource too large: " + std::to_string(vertexCount) + " vertices, " +
                     std::to_string(indexCount) + " indices");
  }
  const std::size_t need =
      kShapeHeaderSize + 24u * std::size_t{vertexCount} + 4u * std::size_t{indexCount};
  if (bytes.size() < need) {
    return makeError("shape resource truncated: " + std::to_string(bytes.size()) + " bytes, " +
                     std::to_string(need) + " needed");
  }
  shape.vertices.resize(3u * vertexCount);
  shape.indices.resize(indexCount);
  if (vertexCount > 0) {
    std::memcpy(shape.vertices.data(), bytes.data() + kShapeHeaderSize,
                24u * std::size_t{vertexCount});
  }
  if (indexCount > 0) {
    std::memcpy(shape.indices.data(),
                bytes.data() + kShapeHeaderSize + 24u * std::size_t{vertexCount},
                4u * std::size_t{indexCount});
  }
  if (auto valid = validateShape(shape); !valid.ok()) return valid.error();
  return shape;
}

Aabb localBounds(const Shape& shape) {
  switch (shape.kind) {
    case ShapeKind::Sphere:
      return {{-shape.radius, -shape.radius, -shape.radius},
              {shape.radius, shape.radius, shape.radius}};
    case ShapeKind::Box:
      return {toVec3(asEigen(shape.halfExtents) * -1.0), shape.halfExtents};
    case ShapeKind::Capsule: {
      const double r = shape.radius, h = shape.halfHeight + shape.radius;
      return {{-r, -h, -r}, {r, h, r}};
    }
    case ShapeKind::ConvexHull:
    case ShapeKind::TriangleMesh: {
      Aabb box{{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                std::numeric_limits<double>::infinity()},
               {-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                -std::numeric_limits<double>::infinity()}};
      for (std::size_t i = 0; i + 2 < shape.vertices.size(); i += 3) {
        for (std::size_t k = 0; k < 3; ++k) {
          box.min[k] = std::min(box.min[k], shape.vertices[i + k]);
          box.max[k] = std::max(box.max[k], shape.vertices[i + k]);
        }
      }
      return box;
    }
  }
  return {};
}

Vec3 rotate(const Quat& q, const Vec3& v) {
  // Eigen's q * v: v + 2w (u x v) + 2 u x (u x v), u = (x, y, z).
  return toVec3(asEigen(q) * asEigen(v));
}

Vec3 rotateInverse(const Quat& q, const Vec3& v) {
  return toVec3(asEigen(q).conjugate() * asEigen(v));
}

Aabb worldBounds(const Shape& shape, const Vec3& position, const Quat& orientation) {
  if (shape.kind == ShapeKind::Sphere) {
    const double r = shape.radius;
    const Vector3d extent = Vector3d::Constant(r);
    return {toVec3(asEigen(position) - extent), toVec3(asEigen(position) + extent)};
  }
  if (shape.kind == ShapeKind::Capsule) {
    const Vec3 axis = rotate(orientation, {0.0, shape.halfHeight, 0.0});
    Aabb box;
    for (std::size_t k = 0; k < 3; ++k) {
      const double extent = std::abs(axis[k]) + shape.radius;
      box.min[k] = position[k] - extent;
      box.max[k] = position[k] + extent;
    }
    return box;
  }
  if (shape.kind == ShapeKind::ConvexHull || shape.kind == ShapeKind::TriangleMesh) {
    Aabb box{position, position};
    for (std::size_t i = 0; i + 2 < shape.vertices.size(); i += 3) {
      const Vec3 p =
          toVec3(asEigen(position) + asEigen(orientation) * asVector3(&shape.vertices[i]));
      for (std::size_t k = 0; k < 3; ++k) {
        box.min[k] = std::min(box.min[k], p[k]);
        box.max[k] = std::max(box.max[k], p[k]);
      }
    }
    return box;
  }
  // Box: the rotated half extents' absolute projections.
  const Vec3 ex = rotate(orientation, {shape.halfExtents[0], 0.0, 0.0});
  const Vec3 ey = rotate(orientation, {0.0, shape.halfExtents[1], 0.0});
  const Vec3 ez = rotate(orientation, {0.0, 0.0, shape.halfExtents[2]});
  Aabb box;
  for (std::size_t k = 0; k < 3; ++k) {
    const double extent = std::abs(ex[k]) + std::abs(ey[k]) + std::abs(ez[k]);
    box.min[k] = position[k] - extent;
    box.max[k] = position[k] + extent;
  }
  return box;
}

MassProperties massProperties(const Shape& shape, double mass) {
  MassProperties out;
  const auto diagonal = [&out](double x, double y, double z) {
    out.inertia = {x, 0, 0, 0, y, 0, 0, 0, z};
  };
  switch (shape.kind) {
    case ShapeKind::Sphere: {
      const double r = shape.radius;
      out.volume = 4.0 / 3.0 * std::numbers::pi * r * r * r;
      const double i = 0.4 * mass * r * r;
      diagonal(i, i, i);
      return out;
    }
    case ShapeKind::Box: {
      const Vec3& h = shape.halfExtents;
      out.volume = 8.0 * h[0] * h[1] * h[2];
      diagonal(mass / 3.0 * (h[1] * h[1] + h[2] * h[2]), mass / 3.0 * (h[0] * h[0] + h[2] * h[2]),
               mass / 3.0 * (h[0] * h[0] + h[1] * h[1]));
      return out;
    }
    case ShapeKind::Capsule: {
      const double r = shape.radius, h = 2.0 * shape.halfHeight;
      const double cylinder = std::numbers::pi * r * r * h;
      const double caps = 4.0 / 3.0 * std::numbers::pi * r * r * r;
      out.volume = cylinder + caps;
      const double mc = mass * cylinder / out.volume, ms = mass * caps / out.volume;
      const double axial = mc * r * r / 2.0 + ms * 0.4 * r * r;
      const double transverse =
          mc * (h * h / 12.0 + r * r / 4.0) + ms * (0.4 * r * r + h * h / 4.0 + 3.0 * h * r / 8.0);
      diagonal(transverse, axial, transverse);
      return out;
    }
    case ShapeKind::ConvexHull:
    case ShapeKind::TriangleMesh: {
      // Second moments of the signed tetrahedra (origin, a, b, c):
      // C = det/120 * (sum_i x_i x_i^T + (sum_i x_i)(sum_i x_i)^T), x_i = a, b, c.
      double volume = 0.0;
      std::array<double, 9> cov{};
      for (std::size_t t = 0; t + 2 < shape.indices.size(); t += 3) {
        const Vector3d a = vertex(shape, shape.indices[t]);
        const Vector3d b = vertex(shape, shape.indices[t + 1]);
        const Vector3d c = vertex(shape, shape.indices[t + 2]);
        const double det = a.dot(b.cross(c));
        volume += det / 6.0;
        const Vector3d s = a + b + c;
        for (std::size_t i = 0; i < 3; ++i) {
          for (std::size_t j = 0; j < 3; ++j) {
            cov[3 * i + j] += det / 120.0 * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j]);
          }
        }
      }
      out.volume = std::abs(volume);
      if (out.volume <= 0.0) return out;
      const double density = mass / volume;  // signed: inward-wound meshes still come out right
      const double trace = cov[0] + cov[4] + cov[8];
      for (std::size_t i = 0; i < 3; ++i) {
        for (std::size_t j = 0; j < 3; ++j) {
          out.inertia[3 * i + j] = density * ((i == j ? trace : 0.0) - cov[3 * i + j]);
        }
      }
      return out;
    }
  }
  return out;
}

SurfaceDistance signedDistance(const Shape& shape, const Vec3& p) {
  switch (shape.kind) {
    case ShapeKind::Sphere:
      return {asEigen(p).norm() - shape.radius, toVec3(normalized(asEigen(p), Vector3d::UnitY()))};
    case ShapeKind::Box: {
      const Vec3& h = shape.halfExtents;
      const Vec3 q{std::abs(p[0]) - h[0], std::abs(p[1]) - h[1], std::abs(p[2]) - h[2]};
      const auto sign = [](double v) { return v < 0.0 ? -1.0 : 1.0; };
      if (q[0] > 0.0 || q[1] > 0.0 || q[2] > 0.0) {
        const Vec3 outside{std::max(q[0], 0.0) * sign(p[0]), std::max(q[1], 0.0) * sign(p[1]),
                           std::max(q[2], 0.0) * sign(p[2])};
        return {asEigen(outside).norm(), toVec3(normalized(asEigen(outside), Vector3d::UnitY()))};
      }
      std::size_t axis = 0;
      if (q[1] > q[axis]) axis = 1;
      if (q[2] > q[axis]) axis = 2;
      Vec3 normal{};
      normal[axis] = sign(p[axis]);
      return {q[axis], normal};
    }
    case ShapeKind::Capsule: {
      const Vector3d onAxis{0.0, std::clamp(p[1], -shape.halfHeight, shape.halfHeight), 0.0};
      const Vector3d d = asEigen(p) - onAxis;
      return {d.norm() - shape.radius, toVec3(normalized(d, Vector3d::UnitX()))};
    }
    case ShapeKind::ConvexHull: {
      SurfaceDistance best{-std::numeric_limits<double>::infinity(), {0.0, 1.0, 0.0}};
      for (std::size_t t = 0; t + 2 < shape.indices.size(); t += 3) {
        const Vector3d a = vertex(shape, shape.indices[t]);
        const Vector3d n = normalized((vertex(shape, shape.indices[t + 1]) - a)
                                          .cross(vertex(shape, shape.indices[t + 2]) - a),
                                      Vector3d::Zero());
        if (n == Vector3d::Zero()) continue;  // degenerate triangle
        const double d = (asEigen(p) - a).dot(n);
        if (d > best.distance) best = {d, toVec3(n)};
      }
      return best;
    }
    case ShapeKind::TriangleMesh: {
      double bestSquared = std::numeric_limits<double>::infinity();
      SurfaceDistance best{std::numeric_limits<double>::infinity(), {0.0, 1.0, 0.0}};
      for (std::size_t t = 0; t + 2 < shape.indices.size(); t += 3) {
        const Vector3d a = vertex(shape, shape.indices[t]);
        const Vector3d b = vertex(shape, shape.indices[t + 1]);
        const Vector3d c = vertex(shape, shape.indices[t + 2]);
        const Vector3d d = asEigen(p) - closestOnTriangle(asEigen(p), a, b, c);
        const double squared = d.squaredNorm();
        if (squared >= bestSquared) continue;
        bestSquared = squared;
        const Vector3d faceNormal = normalized((b - a).cross(c - a), Vector3d::UnitY());
        const double side = d.dot(faceNormal) < 0.0 ? -1.0 : 1.0;
        const double dist = std::sqrt(squared);
        best = {side * dist, toVec3(dist > 1e-12 ? Vector3d(d * (side / dist)) : faceNormal)};
      }
      return best;
    }
  }
  return {};
}

RenderMesh renderMesh(const Shape& shape, int segments) {
  switch (shape.kind) {
    case ShapeKind::Sphere:
      return roundMesh(shape.radius, 0.0, segments);
    case ShapeKind::Capsule:
      return roundMesh(shape.radius, shape.halfHeight, segments);
    case ShapeKind::Box:
      return boxMesh(shape.halfExtents);
    case ShapeKind::ConvexHull:
    case ShapeKind::TriangleMesh: {
      RenderMesh mesh;
      mesh.xyz.reserve(shape.vertices.size());
      for (double v : shape.vertices) mesh.xyz.push_back(static_cast<float>(v));
      mesh.indices = shape.indices;
      return mesh;
    }
  }
  return {};
}

}  // namespace vrflow::msg
