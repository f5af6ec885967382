#include <array>
#include <cassert>
#include <cstdint>
#include <map>
#include <unordered_map>

#include "reference_chain.hpp"

namespace vrflow::camera::reference {

namespace {

// Cube corners by bit (x = 1, y = 2, z = 4); the six tetrahedra share the diagonal 0-7 and walk
// to it one axis at a time, so each cube face is split along the same diagonal as its neighbour's.
constexpr std::array<std::array<int, 4>, 6> kTetrahedra = {
    {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}}};

class Mesher {
 public:
  Mesher(const VoxelGrid& grid, const std::vector<float>& sdf)
      : s_(grid.spec), sdf_(sdf), px_(s_.nx + 2), py_(s_.ny + 2), pz_(s_.nz + 2) {
    // Occupancy with a border of outside voxels: grid point (i, j, k), i in [-1, nx].
    inside_.assign(static_cast<std::size_t>(px_) * py_ * pz_, 0);
    for (int k = 0; k < s_.nz; ++k)
      for (int j = 0; j < s_.ny; ++j)
        for (int i = 0; i < s_.nx; ++i) inside_[padded(i, j, k)] = grid.occupied[s_.index(i, j, k)];
  }

  TriangleMesh run() {
    const std::array<std::size_t, 8> offsets = cornerOffsets();
    for (int k = -1; k < s_.nz; ++k)
      for (int j = -1; j < s_.ny; ++j)
        for (int i = -1; i < s_.nx; ++i) {
          const std::size_t base = padded(i, j, k);
          int count = 0;
          for (std::size_t offset : offsets) count += inside_[base + offset];
          if (count == 0 || count == 8) continue;
          for (const auto& tet : kTetrahedra) emitTetrahedron(i, j, k, tet);
        }
    return std::move(mesh_);
  }

 private:
  std::size_t padded(int i, int j, int k) const {
    return (static_cast<std::size_t>(k + 1) * py_ + (j + 1)) * px_ + (i + 1);
  }
  std::array<std::size_t, 8> cornerOffsets() const {
    std::array<std::size_t, 8> offsets{};
    for (int c = 0; c < 8; ++c)
      offsets[c] = padded(c & 1, (c >> 1) & 1, (c >> 2) & 1) - padded(0, 0, 0);
    return offsets;
  }
  float value(int i, int j, int k) const {
    if (i < 0 || j < 0 || k < 0 || i >= s_.nx || j >= s_.ny || k >= s_.nz)
      return static_cast<float>(0.5 * s_.voxelSize);
    return sdf_[s_.index(i, j, k)];
  }

  // The vertex where the field crosses zero on the edge from corner `a` to corner `b` of cube
  // (i, j, k), `b` a superset of `a`'s bits: one per grid edge, shared by the cubes around it.
  int vertex(int i, int j, int k, int a, int b) {
    const std::uint64_t key = padded(i + (a & 1), j + ((a >> 1) & 1), k + ((a >> 2) & 1)) * 8 +
                              static_cast<std::uint64_t>(b & ~a);
    const auto [it, added] = vertices_.try_emplace(key, static_cast<int>(mesh_.vertices.size()));
    if (added) {
      const cv::Vec3i pa(i + (a & 1), j + ((a >> 1) & 1), k + ((a >> 2) & 1));
      const cv::Vec3i pb(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
      const float fa = value(pa[0], pa[1], pa[2]), fb = value(pb[0], pb[1], pb[2]);
      const double t = fa / (fa - fb);
      const cv::Vec3d ca = s_.centre(pa[0], pa[1], pa[2]), cb = s_.centre(pb[0], pb[1], pb[2]);
      mesh_.vertices.emplace_back(ca + t * (cb - ca));
    }
    return it->second;
  }

  void emitTetrahedron(int i, int j, int k, const std::array<int, 4>& tet) {
    std::array<int, 4> in{}, out{};
    int nIn = 0, nOut = 0;
    for (int c : tet) {
      const bool isInside = inside_[padded(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))];
      (isInside ? in[nIn++] : out[nOut++]) = c;
    }
    if (nIn == 0 || nOut == 0) return;
    // Outward: from the inside corners' centroid to the outside corners'.
    cv::Vec3d outward(0, 0, 0);
    for (int n = 0; n < nOut; ++n) outward += cornerPosition(out[n]) / nOut;
    for (int n = 0; n < nIn; ++n) outward -= cornerPosition(in[n]) / nIn;
    auto edge = [&](int a, int b) { return a < b ? vertex(i, j, k, a, b) : vertex(i, j, k, b, a); };
    if (nIn == 1) {
      addTriangle(edge(in[0], out[0]), edge(in[0], out[1]), edge(in[0], out[2]), outward);
    } else if (nIn == 3) {
      addTriangle(edge(in[0], out[0]), edge(in[1], out[0]), edge(in[2], out[0]), outward);
    } else {
      const int ac = edge(in[0], out[0]), ad = edge(in[0], out[1]);
      const int bd = edge(in[1], out[1]), bc = edge(in[1], out[0]);
      addTriangle(ac, ad, bd, outward);
      addTriangle(ac, bd, bc, outward);
    }
  }
  static cv::Vec3d cornerPosition(int c) {
    return {double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)};
  }

  void addTriangle(int a, int b, int c, const cv::Vec3d& outward) {
    const cv::Vec3f& pa = mesh_.vertices[a];
    const cv::Vec3d normal = cv::Vec3d((mesh_.vertices[b] - pa).cross(mesh_.vertices[c] - pa));
    if (normal.dot(outward) < 0) std::swap(b, c);
    mesh_.triangles.emplace_back(a, b, c);
  }

  const GridSpec& s_;
  const std::vector<float>& sdf_;
  int px_, py_, pz_;
  std::vector<std::uint8_t> inside_;
  std::unordered_map<std::uint64_t, int> vertices_;
  TriangleMesh mesh_;
};

}  // namespace

TriangleMesh meshHull(const VoxelGrid& grid, const std::vector<float>& sdf) {
  assert(sdf.size() == grid.spec.count());
  return Mesher(grid, sdf).run();
}

}  // namespace vrflow::camera::reference
