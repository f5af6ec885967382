#include <algorithm>
#include <cmath>

#include "reference_chain.hpp"
#include "vrflow/camera/distance_field.hpp"

namespace vrflow::camera::reference {

namespace {

// One line of the transform: d[q] = min_v f[v] + (q - v)^2 over n samples spaced `stride`
// apart, in place (FH's algorithm, with v, z and a copy of f as scratch).
struct LineTransform {
  std::vector<float> f;
  std::vector<int> v;
  std::vector<double> z;

  explicit LineTransform(int n)
      : f(static_cast<std::size_t>(n)),
        v(static_cast<std::size_t>(n)),
        z(static_cast<std::size_t>(n) + 1) {}

  void operator()(float* data, int n, std::size_t stride) {
    for (int q = 0; q < n; ++q) f[q] = data[q * stride];
    // The lower envelope of the parabolas rooted at the finite samples; z[k] is where the k-th
    // one starts to be the lowest.
    int k = -1;
    for (int q = 0; q < n; ++q) {
      if (f[q] >= kNoVoxel) continue;
      if (k < 0) {
        k = 0;
        v[0] = q;
        z[0] = -1e30;
        z[1] = 1e30;
        continue;
      }
      double s = intersection(v[k], q);
      while (s <= z[k]) s = intersection(v[--k], q);
      ++k;
      v[k] = q;
      z[k] = s;
      z[k + 1] = 1e30;
    }
    if (k < 0) return;  // nothing to spread along this line
    k = 0;
    for (int q = 0; q < n; ++q) {
      while (z[k + 1] < q) ++k;
      const double d = q - v[k];
      data[q * stride] = static_cast<float>(f[v[k]] + d * d);
    }
  }

  double intersection(int p, int q) const {
    return ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * (q - p));
  }
};

}  // namespace

std::vector<float> squaredDistanceTo(const VoxelGrid& grid, std::uint8_t target) {
  const GridSpec& s = grid.spec;
  std::vector<float> d(s.count());
  // Along x: the distance to the nearest target on the line, by two scans (exact in 1D).
  for (int k = 0; k < s.nz; ++k)
    for (int j = 0; j < s.ny; ++j) {
      const std::size_t row = s.index(0, j, k);
      float gap = kNoVoxel;
      for (int i = 0; i < s.nx; ++i) {
        gap = grid.occupied[row + i] == target ? 0.0f : (gap >= kNoVoxel ? kNoVoxel : gap + 1);
        d[row + i] = gap;
      }
      gap = kNoVoxel;
      for (int i = s.nx - 1; i >= 0; --i) {
        gap = grid.occupied[row + i] == target ? 0.0f : (gap >= kNoVoxel ? kNoVoxel : gap + 1);
        if (gap < d[row + i]) d[row + i] = gap;
      }
      for (int i = 0; i < s.nx; ++i)
        if (d[row + i] < kNoVoxel) d[row + i] *= d[row + i];
    }
  // Along y, then z: parabola envelopes.
  LineTransform alongY(s.ny), alongZ(s.nz);
  const std::size_t sliceSize = static_cast<std::size_t>(s.nx) * s.ny;
  for (int k = 0; k < s.nz; ++k)
    for (int i = 0; i < s.nx; ++i)
      alongY(&d[s.index(i, 0, k)], s.ny, static_cast<std::size_t>(s.nx));
  for (int j = 0; j < s.ny; ++j)
    for (int i = 0; i < s.nx; ++i) alongZ(&d[s.index(i, j, 0)], s.nz, sliceSize);
  return d;
}

std::vector<float> signedDistanceField(const VoxelGrid& grid) {
  const GridSpec& s = grid.spec;
  const std::vector<float> toInside = reference::squaredDistanceTo(grid, 1);
  // Only inside voxels need their distance to the outside, and each has a nearest outside voxel
  // in the occupied bounding box grown by one voxel (clamping any other onto that box's border
  // layer, which is outside, brings it no farther): the transform runs on that box alone.
  cv::Vec3i lo(s.nx, s.ny, s.nz), hi(0, 0, 0);
  for (int k = 0; k < s.nz; ++k)
    for (int j = 0; j < s.ny; ++j)
      for (int i = 0; i < s.nx; ++i)
        if (grid.occupied[s.index(i, j, k)]) {
          lo = {std::min(lo[0], i), std::min(lo[1], j), std::min(lo[2], k)};
          hi = {std::max(hi[0], i + 1), std::max(hi[1], j + 1), std::max(hi[2], k + 1)};
        }
  const auto h = static_cast<float>(s.voxelSize);
  std::vector<float> field(s.count());
  for (std::size_t n = 0; n < field.size(); ++n)
    field[n] = toInside[n] >= kNoVoxel ? kNoVoxel : (std::sqrt(toInside[n]) - 0.5f) * h;
  if (hi[0] == 0) return field;  // nothing inside
  lo = {std::max(lo[0] - 1, 0), std::max(lo[1] - 1, 0), std::max(lo[2] - 1, 0)};
  hi = {std::min(hi[0] + 1, s.nx), std::min(hi[1] + 1, s.ny), std::min(hi[2] + 1, s.nz)};
  VoxelGrid box(GridSpec{s.origin, s.voxelSize, hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  for (int k = lo[2]; k < hi[2]; ++k)
    for (int j = lo[1]; j < hi[1]; ++j)
      for (int i = lo[0]; i < hi[0]; ++i)
        box.occupied[box.spec.index(i - lo[0], j - lo[1], k - lo[2])] =
            grid.occupied[s.index(i, j, k)];
  const std::vector<float> toOutside = reference::squaredDistanceTo(box, 0);
  // Beyond the grid counts as outside: an inside voxel is at most its distance to the border
  // plus one from an outside centre.
  for (int k = lo[2]; k < hi[2]; ++k)
    for (int j = lo[1]; j < hi[1]; ++j)
      for (int i = lo[0]; i < hi[0]; ++i) {
        const std::size_t n = s.index(i, j, k);
        if (!grid.occupied[n]) continue;
        const int border = 1 + std::min({i, j, k, s.nx - 1 - i, s.ny - 1 - j, s.nz - 1 - k});
        const float squared = toOutside[box.spec.index(i - lo[0], j - lo[1], k - lo[2])];
        field[n] = -(std::min(std::sqrt(squared), static_cast<float>(border)) - 0.5f) * h;
      }
  return field;
}

}  // namespace vrflow::camera::reference
