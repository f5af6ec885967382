#include "vrflow/rigid/user_contacts.hpp"

#include <algorithm>
#include <cmath>

namespace vrflow::rigid {
namespace {

Vec3 add(const Vec3& a, const Vec3& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}

bool near(const msg::Aabb& a, const msg::Aabb& b, double reach) {
  for (int k = 0; k < 3; ++k)
    if (a.min[k] > b.max[k] + reach || b.min[k] > a.max[k] + reach) return false;
  return true;
}

bool isRound(const msg::Shape& shape) {
  return shape.kind == msg::ShapeKind::Sphere || shape.kind == msg::ShapeKind::Capsule;
}

// The contacts out[first..] of one body with one user, made to push one way: a contact whose
// normal is more than 60 degrees from their mean direction (each weighted by how far inside
// `reach` it is) takes that direction. A body that the user's field partly swallows has samples
// whose nearest surface lies on opposite sides (above and below a hand): their normals oppose, no
// velocity meets both pushes, and the solver's impulses grow until the body is thrown. Normals
// within 60 degrees of one direction are all met by a velocity along it at most twice the
// largest target, and the swallowed part is pushed out the way most of the body sees the surface.
void pushOneWay(std::vector<SurfaceContact>& out, std::size_t first, double reach) {
  Vec3 mean{};
  for (std::size_t i = first; i < out.size(); ++i) {
    const double weight = reach - out[i].distance;
    for (int a = 0; a < 3; ++a) mean[a] += weight * out[i].normal[a];
  }
  const double norm = std::sqrt(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]);
  if (!(norm > 0)) return;
  for (double& x : mean) x /= norm;
  for (std::size_t i = first; i < out.size(); ++i) {
    const Vec3& n = out[i].normal;
    if (n[0] * mean[0] + n[1] * mean[1] + n[2] * mean[2] < 0.5) out[i].normal = mean;
  }
}

}  // namespace

std::vector<Vec3> surfaceSamples(const msg::Shape& shape, double spacing) {
  std::vector<Vec3> samples;
  switch (shape.kind) {
    case msg::ShapeKind::Sphere:
      samples.push_back({0, 0, 0});
      break;
    case msg::ShapeKind::Capsule:
      for (double y : {-shape.halfHeight, 0.0, shape.halfHeight}) samples.push_back({0, y, 0});
      break;
    case msg::ShapeKind::Box: {
      // A grid over each face, corners and edges included (shared points once).
      const Vec3& h = shape.halfExtents;
      std::array<int, 3> cells{};
      for (int a = 0; a < 3; ++a)
        cells[a] = std::clamp(static_cast<int>(std::ceil(2 * h[a] / spacing)), 1, 8);
      for (int i = 0; i <= cells[0]; ++i)
        for (int j = 0; j <= cells[1]; ++j)
          for (int k = 0; k <= cells[2]; ++k) {
            const bool face =
                i == 0 || i == cells[0] || j == 0 || j == cells[1] || k == 0 || k == cells[2];
            if (!face) continue;
            samples.push_back({-h[0] + 2 * h[0] * i / cells[0], -h[1] + 2 * h[1] * j / cells[1],
                               -h[2] + 2 * h[2] * k / cells[2]});
          }
      break;
    }
    case msg::ShapeKind::ConvexHull:
    case msg::ShapeKind::TriangleMesh: {
      const auto& v = shape.vertices;
      for (std::size_t i = 0; i + 2 < v.size(); i += 3)
        samples.push_back({v[i], v[i + 1], v[i + 2]});
      for (std::size_t t = 0; t + 2 < shape.indices.size(); t += 3) {
        Vec3 c{};
        for (std::size_t corner = 0; corner < 3; ++corner)
          for (std::size_t a = 0; a < 3; ++a) c[a] += v[3 * shape.indices[t + corner] + a] / 3.0;
        samples.push_back(c);
      }
      break;
    }
  }
  return samples;
}

void userContacts(const Body& body, double spacing,
                  const std::map<std::uint64_t, const camera::UserSurface*>& users, double reach,
                  std::vector<SurfaceContact>& out) {
  if (body.kinematic) return;
  const msg::Aabb box = msg::worldBounds(body.shape, body.position, body.orientation);
  const double radius = isRound(body.shape) ? body.shape.radius : 0.0;
  std::vector<Vec3> samples;
  for (const auto& [id, user] : users) {
    if (!near(box, user->bounds, reach + user->spacing)) continue;
    if (samples.empty()) samples = surfaceSamples(body.shape, spacing);
    const std::size_t first = out.size();
    for (const Vec3& local : samples) {
      const Vec3 centre = add(body.position, msg::rotate(body.orientation, local));
      const double distance = user->distance(centre) - radius;
      if (distance >= reach) continue;
      const Vec3 normal = user->normal(centre);
      if (normal == Vec3{}) continue;
      const Vec3 point{centre[0] - radius * normal[0], centre[1] - radius * normal[1],
                       centre[2] - radius * normal[2]};
      out.push_back({body.id, id, point, normal, distance, user->velocityAt(point)});
    }
    pushOneWay(out, first, reach);
  }
}

}  // namespace vrflow::rigid
