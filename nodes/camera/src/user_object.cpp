#include "vrflow/camera/user_object.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "vrflow/camera/distance_field.hpp"
#include "vrflow/message/builtin_types.hpp"

namespace vrflow::camera {

UserFrame describeUser(const VoxelGrid& grid, double band, int threads) {
  UserFrame frame;
  const GridSpec& s = grid.spec;
  frame.spec = s;
  frame.sdf = std::isinf(band) ? signedDistanceField(grid, threads)
                               : signedDistanceFieldInBand(grid, band, threads);
  frame.mesh = meshHull(grid, frame.sdf);
  double sum[3] = {0, 0, 0};
  int lo[3] = {s.nx, s.ny, s.nz}, hi[3] = {-1, -1, -1};
  for (int k = 0; k < s.nz; ++k)
    for (int j = 0; j < s.ny; ++j)
      for (int i = 0; i < s.nx; ++i) {
        if (grid.occupied[s.index(i, j, k)] == 0) continue;
        ++frame.voxels;
        const int at[3] = {i, j, k};
        for (int a = 0; a < 3; ++a) {
          sum[a] += at[a] + 0.5;
          lo[a] = std::min(lo[a], at[a]);
          hi[a] = std::max(hi[a], at[a]);
        }
      }
  for (int a = 0; a < 3; ++a) {
    const int cells = a == 0 ? s.nx : a == 1 ? s.ny : s.nz;
    if (frame.voxels == 0) {
      frame.position[a] = s.origin[a] + 0.5 * cells * s.voxelSize;
      frame.bounds.min[a] = frame.bounds.max[a] = frame.position[a];
      continue;
    }
    frame.position[a] = s.origin[a] + sum[a] / static_cast<double>(frame.voxels) * s.voxelSize;
    frame.bounds.min[a] = s.origin[a] + lo[a] * s.voxelSize;
    frame.bounds.max[a] = s.origin[a] + (hi[a] + 1) * s.voxelSize;
  }
  return frame;
}

void writeUser(msg::MessageBuilder& builder, const UserIds& ids, const UserFrame& frame, bool add) {
  using P = msg::UserParam;
  const GridSpec& s = frame.spec;
  std::vector<float> xyz;
  xyz.reserve(3 * frame.mesh.vertices.size());
  for (const auto& v : frame.mesh.vertices) xyz.insert(xyz.end(), {v[0], v[1], v[2]});
  std::vector<std::uint32_t> indices;
  indices.reserve(3 * frame.mesh.triangles.size());
  for (const auto& t : frame.mesh.triangles)
    for (int c = 0; c < 3; ++c) indices.push_back(static_cast<std::uint32_t>(t[c]));
  builder.addMesh(ids.mesh, true, xyz, indices);
  const std::array<std::uint32_t, 3> dims{static_cast<std::uint32_t>(s.nx),
                                          static_cast<std::uint32_t>(s.ny),
                                          static_cast<std::uint32_t>(s.nz)};
  const cv::Vec3d first = s.centre(0, 0, 0);
  const msg::Vec3 origin{first[0], first[1], first[2]};
  builder.addField(ids.sdf, true, dims, 1, origin, s.voxelSize, frame.sdf);
  const bool velocity = !frame.velocity.empty();
  if (velocity) builder.addField(ids.velocity, true, dims, 3, origin, s.voxelSize, frame.velocity);
  auto object = builder.addObject(ids.object, msg::userType(),
                                  add ? msg::ObjectOp::Add : msg::ObjectOp::Update);
  object.set(P::kPosition, frame.position).set(P::kBounds, frame.bounds);
  if (!add) return;
  object.set(P::kOrientation, msg::Quat{0, 0, 0, 1}).set(P::kMesh, ids.mesh).set(P::kSdf, ids.sdf);
  if (velocity) object.set(P::kVelocityField, ids.velocity);
}

}  // namespace vrflow::camera
