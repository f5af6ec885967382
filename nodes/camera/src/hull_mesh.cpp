#include "vrflow/camera/hull_mesh.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cstdint>
#include <map>

namespace vrflow::camera {

namespace {

// Cube corners by bit (x = 1, y = 2, z = 4); the six tetrahedra share the diagonal 0-7 and walk
// to it one axis at a time, so each cube face is split along the same diagonal as its neighbour's.
constexpr std::array<std::array<int, 4>, 6> kTetrahedra = {
    {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}}};

// Marches the cubes between voxel centres in z, y, x order, visiting only the cubes that touch
// the occupied voxels' bounding box and, in each row of cubes, only the mixed ones (the row's
// four voxel rows summed once). A vertex belongs to a grid edge, keyed by its lower end point
// and direction (b & ~a: 1 to 7); the cubes of layer k reach the points of layers k and k + 1
// only, so two layers of keys, reused by parity, hold every vertex still to be shared. A key is
// valid when its vertex was made after layer k - 1 began: older ones belong to layer k - 2.
class Mesher {
 public:
  Mesher(const VoxelGrid& grid, const std::vector<float>& sdf)
      : s_(grid.spec), sdf_(sdf), px_(s_.nx + 2), py_(s_.ny + 2), pz_(s_.nz + 2) {
    // Occupancy with a border of outside voxels: grid point (i, j, k), i in [-1, nx].
    inside_.assign(static_cast<std::size_t>(px_) * py_ * pz_, 0);
    lo_ = {s_.nx, s_.ny, s_.nz};
    hi_ = {-1, -1, -1};
    for (int k = 0; k < s_.nz; ++k)
      for (int j = 0; j < s_.ny; ++j) {
        const std::uint8_t* row = &grid.occupied[s_.index(0, j, k)];
        std::uint8_t any = 0;
        for (int i = 0; i < s_.nx; ++i) {
          inside_[padded(i, j, k)] = row[i];
          any |= row[i];
          if (row[i]) lo_[0] = std::min(lo_[0], i), hi_[0] = std::max(hi_[0], i);
        }
        if (any)
          lo_[1] = std::min(lo_[1], j), hi_[1] = std::max(hi_[1], j), lo_[2] = std::min(lo_[2], k),
          hi_[2] = std::max(hi_[2], k);
      }
    for (auto& layer : keys_) layer.assign(static_cast<std::size_t>(px_) * py_ * 8, -1);
  }

  TriangleMesh run() {
    if (hi_[0] < 0) return std::move(mesh_);  // nothing inside: no surface
    // Cube (i, j, k) has the corners i..i+1: it touches the box when i is in [lo - 1, hi].
    const int i0 = lo_[0] - 1, i1 = hi_[0] + 1;
    std::vector<int> columnSum(static_cast<std::size_t>(i1 - i0 + 1));
    for (int k = lo_[2] - 1; k <= hi_[2]; ++k) {
      layerStart_[(k + 1) & 1] = static_cast<int>(mesh_.vertices.size());
      for (int j = lo_[1] - 1; j <= hi_[1]; ++j) {
        // Inside corners of each column (i, j..j+1, k..k+1), then of each cube: two columns.
        const std::uint8_t* rows[4] = {&inside_[padded(i0, j, k)], &inside_[padded(i0, j + 1, k)],
                                       &inside_[padded(i0, j, k + 1)],
                                       &inside_[padded(i0, j + 1, k + 1)]};
        for (std::size_t c = 0; c < columnSum.size(); ++c)
          columnSum[c] = rows[0][c] + rows[1][c] + rows[2][c] + rows[3][c];
        for (int i = i0; i < i1; ++i) {
          const auto c = static_cast<std::size_t>(i - i0);
          const int count = columnSum[c] + columnSum[c + 1];
          if (count == 0 || count == 8) continue;
          for (const auto& tet : kTetrahedra) emitTetrahedron(i, j, k, tet);
        }
      }
    }
    return std::move(mesh_);
  }

 private:
  std::size_t padded(int i, int j, int k) const {
    return (static_cast<std::size_t>(k + 1) * py_ + (j + 1)) * px_ + (i + 1);
  }
  float value(int i, int j, int k) const {
    if (i < 0 || j < 0 || k < 0 || i >= s_.nx || j >= s_.ny || k >= s_.nz)
      return static_cast<float>(0.5 * s_.voxelSize);
    return sdf_[s_.index(i, j, k)];
  }

  // The vertex where the field crosses zero on the edge from corner `a` to corner `b` of cube
  // (i, j, k), `b` a superset of `a`'s bits: one per grid edge, shared by the cubes around it.
  int vertex(int i, int j, int k, int a, int b) {
    const cv::Vec3i pa(i + (a & 1), j + ((a >> 1) & 1), k + ((a >> 2) & 1));
    const std::size_t layer = static_cast<std::size_t>(pa[2] + 1) & 1;
    int& key = keys_[layer][((static_cast<std::size_t>(pa[1] + 1) * px_) + (pa[0] + 1)) * 8 +
                            static_cast<std::size_t>(b & ~a)];
    if (key >= layerStart_[layer ^ 1] && key >= 0) return key;
    key = static_cast<int>(mesh_.vertices.size());
    const cv::Vec3i pb(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
    const float fa = value(pa[0], pa[1], pa[2]), fb = value(pb[0], pb[1], pb[2]);
    const double t = fa / (fa - fb);
    const cv::Vec3d ca = s_.centre(pa[0], pa[1], pa[2]), cb = s_.centre(pb[0], pb[1], pb[2]);
    mesh_.vertices.emplace_back(ca + t * (cb - ca));
    return key;
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
  cv::Vec3i lo_, hi_;  // the occupied voxels' box, inclusive
  // Vertex per (point, direction) of the point layers of even and odd padded z.
  std::array<std::vector<int>, 2> keys_;
  std::array<int, 2> layerStart_{0, 0};  // vertex count when the cube layer of that parity began
  TriangleMesh mesh_;
};

}  // namespace

double TriangleMesh::volume() const {
  double sum = 0;
  for (const cv::Vec3i& t : triangles) {
    const cv::Vec3d a(vertices[t[0]]), b(vertices[t[1]]), c(vertices[t[2]]);
    sum += a.dot(b.cross(c));
  }
  return sum / 6.0;
}

bool TriangleMesh::isClosed() const {
  std::map<std::pair<int, int>, int> directed;
  for (const cv::Vec3i& t : triangles)
    for (int e = 0; e < 3; ++e) ++directed[{t[e], t[(e + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    if (count != 1) return false;
    const auto reverse = directed.find({edge.second, edge.first});
    if (reverse == directed.end() || reverse->second != 1) return false;
  }
  return true;
}

TriangleMesh meshHull(const VoxelGrid& grid, const std::vector<float>& sdf) {
  assert(sdf.size() == grid.spec.count());
  return Mesher(grid, sdf).run();
}

}  // namespace vrflow::camera
