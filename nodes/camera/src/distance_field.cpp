#include "vrflow/camera/distance_field.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "parallel_parts.hpp"

namespace vrflow::camera {

namespace {

// Squared distances in voxels^2 are integers: the transform runs on int32 and is exact.
using Squared = std::int32_t;
constexpr Squared kFar = std::numeric_limits<Squared>::max();

// One line of the transform in place over n contiguous samples: d[q] = min_v f[v] + (q - v)^2
// (Felzenszwalb and Huttenlocher's lower envelope of the parabolas rooted at the finite samples).
// The scratch is sized once per part, never per line.
class LineEnvelope {
 public:
  explicit LineEnvelope(int n)
      : f_(static_cast<std::size_t>(n)),
        v_(static_cast<std::size_t>(n)),
        z_(static_cast<std::size_t>(n) + 1) {}

  void operator()(Squared* data, int n) {
    // z_[k] is where the k-th parabola starts to be the lowest.
    int k = -1;
    for (int q = 0; q < n; ++q) {
      const Squared value = data[q];
      f_[q] = value;
      if (value == kFar) continue;
      if (k < 0) {
        k = 0;
        v_[0] = q;
        z_[0] = -1e30;
        z_[1] = 1e30;
        continue;
      }
      double s = intersection(v_[k], q);
      while (s <= z_[k]) s = intersection(v_[--k], q);
      ++k;
      v_[k] = q;
      z_[k] = s;
      z_[k + 1] = 1e30;
    }
    if (k < 0) return;  // nothing to spread along this line
    k = 0;
    for (int q = 0; q < n; ++q) {
      while (z_[k + 1] < q) ++k;
      const Squared d = q - v_[k];
      data[q] = f_[v_[k]] + d * d;
    }
  }

 private:
  double intersection(int p, int q) const {
    return (static_cast<double>(f_[q]) + double(q) * q -
            (static_cast<double>(f_[p]) + double(p) * p)) /
           (2.0 * (q - p));
  }

  std::vector<Squared> f_;
  std::vector<int> v_;
  std::vector<double> z_;
};

// The box [lo, hi) of a grid whose transform is computed, and the output's layout over it.
struct Box {
  cv::Vec3i lo, hi;
  int nx() const { return hi[0] - lo[0]; }
  int ny() const { return hi[1] - lo[1]; }
  int nz() const { return hi[2] - lo[2]; }
  std::size_t slice() const { return static_cast<std::size_t>(nx()) * ny(); }
  std::size_t count() const { return slice() * nz(); }
};

// Along x by two scans (exact in 1D), then along y by the envelope over each column, one z
// slice at a time: the slice is transposed into the scratch so that every line is contiguous.
// Returns whether the slice holds a target voxel.
bool transformSlice(const VoxelGrid& grid, const Box& box, std::uint8_t target, int k,
                    Squared* slice, std::vector<Squared>& transposed, LineEnvelope& alongY) {
  const GridSpec& s = grid.spec;
  const int nx = box.nx(), ny = box.ny();
  bool any = false;
  for (int j = 0; j < ny; ++j) {
    const std::uint8_t* occupied = &grid.occupied[s.index(box.lo[0], box.lo[1] + j, k)];
    Squared* row = slice + static_cast<std::size_t>(j) * nx;
    Squared gap = kFar;
    for (int i = 0; i < nx; ++i) {
      gap = occupied[i] == target ? 0 : (gap == kFar ? kFar : gap + 1);
      row[i] = gap;
    }
    if (gap == kFar) continue;  // no target on the row: it stays far
    any = true;
    gap = kFar;
    for (int i = nx - 1; i >= 0; --i) {
      gap = occupied[i] == target ? 0 : (gap == kFar ? kFar : gap + 1);
      row[i] = std::min(row[i], gap);
    }
    for (int i = 0; i < nx; ++i) row[i] *= row[i];
  }
  if (!any) return false;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      transposed[static_cast<std::size_t>(i) * ny + j] =
          slice[static_cast<std::size_t>(j) * nx + i];
  for (int i = 0; i < nx; ++i) alongY(&transposed[static_cast<std::size_t>(i) * ny], ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      slice[static_cast<std::size_t>(j) * nx + i] =
          transposed[static_cast<std::size_t>(i) * ny + j];
  return true;
}

// The squared distance from every voxel of `box` to the nearest voxel of the box whose occupancy
// is `target`, laid out over the box (x fastest). Slices of z, then planes of y, split in parts.
std::vector<Squared> transformBox(const VoxelGrid& grid, const Box& box, std::uint8_t target,
                                  int threads) {
  std::vector<Squared> d(box.count());
  const int nx = box.nx(), ny = box.ny(), nz = box.nz();
  const std::size_t sliceSize = box.slice();
  std::vector<std::uint8_t> sliceHasTarget(static_cast<std::size_t>(nz), 0);
  forParts(threads, static_cast<std::size_t>(nz), [&](std::size_t begin, std::size_t end) {
    std::vector<Squared> transposed(sliceSize);
    LineEnvelope alongY(ny);
    for (std::size_t k = begin; k < end; ++k)
      sliceHasTarget[k] = transformSlice(grid, box, target, box.lo[2] + static_cast<int>(k),
                                         &d[k * sliceSize], transposed, alongY);
  });
  if (std::none_of(sliceHasTarget.begin(), sliceHasTarget.end(), [](auto b) { return b != 0; }))
    return d;  // no target at all: far everywhere
  // Along z: the plane of one y gathered as nx contiguous lines of nz.
  forParts(threads, static_cast<std::size_t>(ny), [&](std::size_t begin, std::size_t end) {
    std::vector<Squared> lines(static_cast<std::size_t>(nx) * nz);
    LineEnvelope alongZ(nz);
    for (std::size_t j = begin; j < end; ++j) {
      for (int k = 0; k < nz; ++k) {
        const Squared* row = &d[static_cast<std::size_t>(k) * sliceSize + j * nx];
        for (int i = 0; i < nx; ++i) lines[static_cast<std::size_t>(i) * nz + k] = row[i];
      }
      for (int i = 0; i < nx; ++i) alongZ(&lines[static_cast<std::size_t>(i) * nz], nz);
      for (int k = 0; k < nz; ++k) {
        Squared* row = &d[static_cast<std::size_t>(k) * sliceSize + j * nx];
        for (int i = 0; i < nx; ++i) row[i] = lines[static_cast<std::size_t>(i) * nz + k];
      }
    }
  });
  return d;
}

Box wholeGrid(const GridSpec& s) {
  return {{0, 0, 0}, {s.nx, s.ny, s.nz}};
}

// The occupied voxels' bounding box grown by one voxel within the grid; empty (hi = lo) when
// nothing is occupied.
Box occupiedBox(const VoxelGrid& grid) {
  const GridSpec& s = grid.spec;
  cv::Vec3i lo(s.nx, s.ny, s.nz), hi(0, 0, 0);
  for (int k = 0; k < s.nz; ++k)
    for (int j = 0; j < s.ny; ++j) {
      const std::uint8_t* row = &grid.occupied[s.index(0, j, k)];
      const std::uint8_t* first = std::find(row, row + s.nx, std::uint8_t{1});
      if (first == row + s.nx) continue;
      const auto last = std::find(std::make_reverse_iterator(row + s.nx),
                                  std::make_reverse_iterator(row), std::uint8_t{1});
      lo = {std::min(lo[0], static_cast<int>(first - row)), std::min(lo[1], j), std::min(lo[2], k)};
      hi = {std::max(hi[0], static_cast<int>(last.base() - row)), std::max(hi[1], j + 1),
            std::max(hi[2], k + 1)};
    }
  if (hi[0] == 0) return {{0, 0, 0}, {0, 0, 0}};
  return {{std::max(lo[0] - 1, 0), std::max(lo[1] - 1, 0), std::max(lo[2] - 1, 0)},
          {std::min(hi[0] + 1, s.nx), std::min(hi[1] + 1, s.ny), std::min(hi[2] + 1, s.nz)}};
}

float toFloat(Squared squared) {
  return squared == kFar ? kNoVoxel : static_cast<float>(squared);
}

}  // namespace

std::vector<float> squaredDistanceTo(const VoxelGrid& grid, std::uint8_t target, int threads) {
  const std::vector<Squared> squared = transformBox(grid, wholeGrid(grid.spec), target, threads);
  std::vector<float> d(squared.size());
  std::transform(squared.begin(), squared.end(), d.begin(), toFloat);
  return d;
}

std::vector<float> signedDistanceField(const VoxelGrid& grid, int threads) {
  const GridSpec& s = grid.spec;
  const std::vector<Squared> toInside = transformBox(grid, wholeGrid(s), 1, threads);
  const auto h = static_cast<float>(s.voxelSize);
  std::vector<float> field(s.count());
  forParts(threads, field.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t n = begin; n < end; ++n)
      field[n] =
          toInside[n] == kFar ? kNoVoxel : (std::sqrt(static_cast<float>(toInside[n])) - 0.5f) * h;
  });
  // Only inside voxels need their distance to the outside, and each has a nearest outside voxel
  // in the occupied bounding box grown by one voxel (clamping any other onto that box's border
  // layer, which is outside, brings it no farther): the transform runs on that box alone.
  const Box box = occupiedBox(grid);
  if (box.count() == 0) return field;  // nothing inside
  const std::vector<Squared> toOutside = transformBox(grid, box, 0, threads);
  // Beyond the grid counts as outside: an inside voxel is at most its distance to the border
  // plus one from an outside centre.
  for (int k = box.lo[2]; k < box.hi[2]; ++k)
    for (int j = box.lo[1]; j < box.hi[1]; ++j) {
      const std::size_t boxRow = static_cast<std::size_t>(k - box.lo[2]) * box.slice() +
                                 static_cast<std::size_t>(j - box.lo[1]) * box.nx() - box.lo[0];
      for (int i = box.lo[0]; i < box.hi[0]; ++i) {
        const std::size_t n = s.index(i, j, k);
        if (!grid.occupied[n]) continue;
        const int border = 1 + std::min({i, j, k, s.nx - 1 - i, s.ny - 1 - j, s.nz - 1 - k});
        const auto squared = static_cast<float>(toOutside[boxRow + i]);
        field[n] = -(std::min(std::sqrt(squared), static_cast<float>(border)) - 0.5f) * h;
      }
    }
  return field;
}

}  // namespace vrflow::camera
