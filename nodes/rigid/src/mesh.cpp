#include "vrflow/rigid/mesh.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <string>
#include <utility>

namespace vrflow::rigid {
namespace {

Eigen::Vector3d vertexOf(const msg::Shape& mesh, std::uint32_t i) {
  return {mesh.vertices[3 * std::size_t{i}], mesh.vertices[3 * std::size_t{i} + 1],
          mesh.vertices[3 * std::size_t{i} + 2]};
}

std::string edgeName(std::uint32_t a, std::uint32_t b) {
  return "edge " + std::to_string(a) + "-" + std::to_string(b);
}

}  // namespace

Status checkClosedMesh(const msg::Shape& mesh) {
  if (auto status = msg::validateShape(mesh); !status) return status;
  if (mesh.kind != msg::ShapeKind::TriangleMesh) return makeError("not a triangle mesh");
  // Directed edges: a closed, consistently wound mesh runs along each edge once per direction.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::uint32_t i[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
    const Eigen::Vector3d a = vertexOf(mesh, i[0]);
    const Eigen::Vector3d cross = (vertexOf(mesh, i[1]) - a).cross(vertexOf(mesh, i[2]) - a);
    const double scale = std::max({(vertexOf(mesh, i[1]) - a).squaredNorm(),
                                   (vertexOf(mesh, i[2]) - a).squaredNorm(), 1e-300});
    if (!(cross.norm() > 1e-12 * scale))
      return makeError("triangle " + std::to_string(t / 3) + " is degenerate (zero area)");
    for (int k = 0; k < 3; ++k) ++directed[{i[k], i[(k + 1) % 3]}];
  }
  for (const auto& [edge, count] : directed) {
    if (count > 1)
      return makeError(edgeName(edge.first, edge.second) +
                       " is used twice in the same direction (inconsistent winding or more than "
                       "two triangles on one edge)");
    if (!directed.contains({edge.second, edge.first}))
      return makeError("the mesh is not closed: " + edgeName(edge.first, edge.second) +
                       " has a triangle on one side only (a dynamic mesh must enclose a volume)");
  }
  std::vector<Eigen::Vector3d> vertices;
  for (std::size_t i = 0; i + 2 < mesh.vertices.size(); i += 3)
    vertices.push_back(vertexOf(mesh, static_cast<std::uint32_t>(i / 3)));
  if (auto centroid = volumeCentroid(vertices, mesh.indices); !centroid) return centroid.error();
  return {};
}

Result<Eigen::Vector3d> volumeCentroid(const std::vector<Eigen::Vector3d>& vertices,
                                       const std::vector<std::uint32_t>& triangles) {
  if (vertices.empty()) return makeError("the mesh has no vertices");
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& v : vertices) mean += v;
  mean *= 1.0 / static_cast<double>(vertices.size());
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double volume = 0;
  double extent = 0;
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    const Eigen::Vector3d a = vertices[triangles[t]] - mean, b = vertices[triangles[t + 1]] - mean,
                          d = vertices[triangles[t + 2]] - mean;
    const double v6 = a.dot(b.cross(d));
    volume += v6;
    c += (a + b + d) * (v6 / 4.0);
    extent = std::max({extent, a.squaredNorm(), b.squaredNorm(), d.squaredNorm()});
  }
  // Relative to the size of the mesh, so that a flat (or cancelling) surface is caught.
  if (!(std::abs(volume) > 1e-12 * extent * std::sqrt(extent)))
    return makeError("the mesh encloses no volume");
  return Eigen::Vector3d(mean + c * (1.0 / volume));
}

Result<msg::Shape> centredMesh(const msg::Shape& mesh, Vec3* centroid) {
  if (auto status = checkClosedMesh(mesh); !status) return status.error();
  std::vector<Eigen::Vector3d> vertices;
  for (std::size_t i = 0; i + 2 < mesh.vertices.size(); i += 3)
    vertices.push_back(vertexOf(mesh, static_cast<std::uint32_t>(i / 3)));
  auto shift = volumeCentroid(vertices, mesh.indices);
  if (!shift) return shift.error();
  std::vector<double> xyz;
  xyz.reserve(mesh.vertices.size());
  for (const auto& v : vertices) {
    const Eigen::Vector3d r = v - *shift;
    xyz.insert(xyz.end(), r.data(), r.data() + 3);
  }
  if (centroid) *centroid = msg::toVec3(*shift);
  return msg::Shape::triangleMesh(std::move(xyz), mesh.indices);
}

std::uint32_t QuadMeshBuilder::vertex(const Vec3& p) {
  vertices_.insert(vertices_.end(), p.begin(), p.end());
  return static_cast<std::uint32_t>(vertices_.size() / 3 - 1);
}

void QuadMeshBuilder::quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d,
                           const Vec3& outward) {
  const auto at = [this](std::uint32_t i) {
    return Eigen::Vector3d(vertices_[3 * std::size_t{i}], vertices_[3 * std::size_t{i} + 1],
                           vertices_[3 * std::size_t{i} + 2]);
  };
  const bool flip = (at(b) - at(a)).cross(at(c) - at(a)).dot(asEigen(outward)) < 0;
  for (std::uint32_t i : flip ? std::array{a, c, b, a, d, c} : std::array{a, b, c, a, c, d})
    indices_.push_back(i);
}

msg::Shape QuadMeshBuilder::shape() const {
  return msg::Shape::triangleMesh(vertices_, indices_);
}

msg::Shape bowlMesh(double halfWidth, double height, double wall) {
  QuadMeshBuilder mesh;
  const double inner = halfWidth - wall;
  // Corners of the outer and inner squares, going round the y axis.
  const std::array<double, 4> sx{-1, 1, 1, -1}, sz{-1, -1, 1, 1};
  std::array<std::uint32_t, 4> outerBottom{}, outerTop{}, innerTop{}, innerBottom{};
  for (std::size_t k = 0; k < 4; ++k) {
    outerBottom[k] = mesh.vertex({halfWidth * sx[k], 0, halfWidth * sz[k]});
    outerTop[k] = mesh.vertex({halfWidth * sx[k], height, halfWidth * sz[k]});
    innerTop[k] = mesh.vertex({inner * sx[k], height, inner * sz[k]});
    innerBottom[k] = mesh.vertex({inner * sx[k], wall, inner * sz[k]});
  }
  const Vec3 up{0, 1, 0}, down{0, -1, 0};
  mesh.quad(outerBottom[0], outerBottom[1], outerBottom[2], outerBottom[3], down);
  mesh.quad(innerBottom[0], innerBottom[1], innerBottom[2], innerBottom[3], up);
  for (std::size_t k = 0; k < 4; ++k) {
    const std::size_t next = (k + 1) % 4;
    // The side's outward direction: from the axis to the middle of the edge k -> next.
    const Vec3 side{sx[k] + sx[next], 0, sz[k] + sz[next]};
    const Vec3 inward{-side[0], 0, -side[2]};
    mesh.quad(outerBottom[k], outerBottom[next], outerTop[next], outerTop[k], side);
    mesh.quad(outerTop[k], outerTop[next], innerTop[next], innerTop[k], up);
    mesh.quad(innerTop[k], innerTop[next], innerBottom[next], innerBottom[k], inward);
  }
  return mesh.shape();
}

}  // namespace vrflow::rigid
