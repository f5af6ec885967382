#include "vrflow/camera/distance_field.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <memory>
#include <type_traits>
#include <utility>

#include "parallel_parts.hpp"

namespace vrflow::camera {

namespace {

// Squared distances in voxels^2 are integers: the transform runs on int32 and is exact.
using Squared = std::int32_t;
constexpr Squared kFar = std::numeric_limits<Squared>::max();

// One line of the transform in place over n contiguous samples: d[q] = min_v f[v] + (q - v)^2
// (Felzenszwalb and Huttenlocher's lower envelope of the parabolas rooted at the finite samples).
// The intersections are compared by cross-multiplying integers, without a division: the
// envelope is the one the rational intersections give. The scratch is sized once per part.
//
// Samples over `limit` count as far, and an output over it may be any value over it: an output
// within the limit comes from a sample within it (f[v] <= d[q]), so it is exact. The whole
// transform keeps that: every value within the limit is exact, every other is over it.
class LineEnvelope {
 public:
  LineEnvelope(int n, Squared limit)
      : v_(static_cast<std::size_t>(n)), f_(static_cast<std::size_t>(n)), limit_(limit) {
    reach_ = static_cast<int>(std::sqrt(static_cast<double>(limit)));
    while (std::int64_t{reach_ + 1} * (reach_ + 1) <= limit) ++reach_;
    while (std::int64_t{reach_} * reach_ > limit) --reach_;
  }

  /// How far a sample within the limit can spread a value within it.
  int reach() const { return reach_; }

  void operator()(Squared* data, int n) {
    // A line of targets only stays so (most of the inside transform's lines; a scan is cheaper
    // than the envelope).
    if (std::all_of(data, data + n, [](Squared d) { return d == 0; })) return;
    // v_[0..k]: the roots of the envelope's parabolas, left to right; f_: their f + v^2.
    int k = -1;
    for (int q = 0; q < n; ++q) {
      if (data[q] > limit_) continue;
      const std::int64_t fq = std::int64_t{data[q]} + std::int64_t{q} * q;
      // Parabola k is hidden when q's intersection with it is not right of its own with k - 1.
      while (k > 0 && (fq - f_[k]) * (v_[k] - v_[k - 1]) <= (f_[k] - f_[k - 1]) * (q - v_[k])) --k;
      ++k;
      v_[k] = q;
      f_[k] = fq;
    }
    if (k < 0) return;  // nothing to spread along this line
    // Parabola m + 1 is below parabola m from their intersection on: from the first sample q
    // with f_[m + 1] - f_[m] <= 2 q (v_[m + 1] - v_[m]), compared in integers (no division).
    // Samples over `reach_` from every root are over the limit and keep their input, which was.
    const int first = static_cast<int>(std::max<std::int64_t>(v_[0] - reach_, 0));
    const int last = static_cast<int>(std::min<std::int64_t>(v_[k] + reach_ + 1, n));
    int m = 0;
    for (int q = first; q < last; ++q) {
      while (m < k && f_[m + 1] - f_[m] <= 2 * std::int64_t{q} * (v_[m + 1] - v_[m])) ++m;
      const std::int64_t d = q - v_[m];
      data[q] = static_cast<Squared>(f_[m] - v_[m] * v_[m] + d * d);
    }
  }

 private:
  std::vector<std::int64_t> v_;
  std::vector<std::int64_t> f_;
  Squared limit_;
  int reach_;
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

// The 1D distance along z (in voxels) from every voxel of the box to the nearest target voxel
// of its column, by a forward and a backward scan over whole rows of columns at once (slices in
// order: contiguous and vectorisable); kFarGap where the column has no target.
// With `columns`, only the columns of each row that hold a target are scanned (the others have
// no target: the caller takes them as far without reading them).
using Gap = std::uint16_t;
constexpr Gap kFarGap = std::numeric_limits<Gap>::max();

// Per grid row j, the columns [begin[j], end[j]) that hold an occupied voxel in some slice
// (begin >= end: none).
struct Columns {
  std::vector<int> begin, end;
};

// The part [from, to) of the box's row j that `columns` (all when null) may hold targets in.
std::pair<int, int> rowColumns(const Box& box, const Columns* columns, int j) {
  if (columns == nullptr) return {0, box.nx()};
  const auto at = static_cast<std::size_t>(box.lo[1] + j);
  const int from = std::clamp(columns->begin[at] - box.lo[0], 0, box.nx());
  return {from, std::clamp(columns->end[at] - box.lo[0], from, box.nx())};
}

void gapsAlongZ(const VoxelGrid& grid, const Box& box, std::uint8_t target, Gap* gaps,
                const Columns* columns, int threads) {
  const GridSpec& s = grid.spec;
  const int nx = box.nx(), ny = box.ny(), nz = box.nz();
  const std::size_t sliceSize = box.slice();
  forParts(threads, static_cast<std::size_t>(ny), [&](std::size_t jBegin, std::size_t jEnd) {
    const std::size_t rows = jEnd - jBegin;
    std::vector<Gap> run(rows * nx);
    // `backward` is a type: each scan's loop is compiled without the branch.
    auto scan = [&](int k, auto backward) {
      for (std::size_t j = jBegin; j < jEnd; ++j) {
        const std::uint8_t* occupied =
            &grid.occupied[s.index(box.lo[0], box.lo[1] + static_cast<int>(j), box.lo[2] + k)];
        Gap* gap = &run[(j - jBegin) * nx];
        Gap* out = &gaps[static_cast<std::size_t>(k) * sliceSize + j * nx];
        const auto [from, to] = rowColumns(box, columns, static_cast<int>(j));
        for (int i = from; i < to; ++i) {
          const Gap next = static_cast<Gap>(gap[i] + (gap[i] != kFarGap));
          gap[i] = occupied[i] == target ? Gap{0} : next;
          if constexpr (decltype(backward)::value)
            out[i] = std::min(out[i], gap[i]);
          else
            out[i] = gap[i];
        }
      }
    };
    std::fill(run.begin(), run.end(), kFarGap);
    for (int k = 0; k < nz; ++k) scan(k, std::false_type{});
    std::fill(run.begin(), run.end(), kFarGap);
    for (int k = nz - 1; k >= 0; --k) scan(k, std::true_type{});
  });
}

// The exact squared distance over the box to the nearest target voxel of the box: the gaps
// along z, then per z slice the envelope along x (contiguous rows) and along y (the slice
// transposed into the scratch). Values within `limit` are exact, the others are over it
// (LineEnvelope); kNoLimit: all exact. Per slice, only the rectangle within the envelope's reach
// of the samples within the limit is transposed, spread along y and emitted: every row (j, k)
// of the box that holds a value within the limit goes to emit(j, k, row, iBegin, iEnd) with the
// columns [iBegin, iEnd) that may (the caller has the rest as over the limit already).
// kToNonTargets: the caller reads only the voxels that are not targets, so only the rectangle of
// those is spread along y and emitted (the rows along x are whole, so it needs no margin).
constexpr Squared kNoLimit = kFar - 1;

// `columns` (null: all): where the targets may be, for the gaps along z.
template <bool kToNonTargets = false, typename Emit>
void transformBox(const VoxelGrid& grid, const Box& box, std::uint8_t target, int threads,
                  Squared limit, const Columns* columns, Emit&& emit) {
  const int nx = box.nx(), ny = box.ny(), nz = box.nz();
  const std::size_t sliceSize = box.slice();
  assert(nz < kFarGap);
  // Every element read is written first (the rows' columns of `columns`).
  std::unique_ptr<Gap[]> gaps(new Gap[box.count()]);
  gapsAlongZ(grid, box, target, gaps.get(), columns, threads);
  forParts(threads, static_cast<std::size_t>(nz), [&](std::size_t kBegin, std::size_t kEnd) {
    std::vector<Squared> slice(sliceSize), transposed(sliceSize);
    LineEnvelope alongX(nx, limit), alongY(ny, limit);
    // The samples that make the rectangle.
    const auto marked = [limit](Squared d) { return kToNonTargets ? d != 0 : d <= limit; };
    for (std::size_t k = kBegin; k < kEnd; ++k) {
      const Gap* gap = &gaps[k * sliceSize];
      int iLo = nx, iHi = -1, jLo = ny, jHi = -1;  // the marked samples
      for (int j = 0; j < ny; ++j) {
        Squared* row = &slice[static_cast<std::size_t>(j) * nx];
        const Gap* rowGap = gap + static_cast<std::size_t>(j) * nx;
        bool rowAny = false;
        const auto [from, to] = rowColumns(box, columns, j);
        std::fill(row, row + from, kFar);
        std::fill(row + to, row + nx, kFar);
        for (int i = from; i < to; ++i) {
          const Squared g = rowGap[i];
          row[i] = g == kFarGap ? kFar : g * g;
          rowAny |= marked(row[i]);
        }
        if (!rowAny) continue;
        iLo = std::min(iLo, static_cast<int>(std::find_if(row, row + nx, marked) - row));
        iHi = std::max(iHi, static_cast<int>(std::find_if(std::make_reverse_iterator(row + nx),
                                                          std::make_reverse_iterator(row), marked)
                                                 .base() -
                                             row) -
                                1);
        jLo = std::min(jLo, j);
        jHi = j;
        alongX(row, nx);
      }
      if (iHi < 0) {
        // Nothing within the limit: all far, which only an unlimited transform emits.
        if (!kToNonTargets && limit == kNoLimit)
          for (int j = 0; j < ny; ++j)
            emit(j, static_cast<int>(k), &slice[static_cast<std::size_t>(j) * nx], 0, nx);
        continue;
      }
      const int margin = kToNonTargets ? 0 : alongX.reach();
      const int iBegin = std::max(iLo - margin, 0), iEnd = std::min(iHi + margin + 1, nx);
      const int jBegin = std::max(jLo - margin, 0), jEnd = std::min(jHi + margin + 1, ny);
      for (int j = 0; j < ny; ++j)
        for (int i = iBegin; i < iEnd; ++i)
          transposed[static_cast<std::size_t>(i) * ny + j] =
              slice[static_cast<std::size_t>(j) * nx + i];
      for (int i = iBegin; i < iEnd; ++i) alongY(&transposed[static_cast<std::size_t>(i) * ny], ny);
      for (int j = jBegin; j < jEnd; ++j) {
        Squared* row = &slice[static_cast<std::size_t>(j) * nx];
        for (int i = iBegin; i < iEnd; ++i)
          row[i] = transposed[static_cast<std::size_t>(i) * ny + j];
        emit(j, static_cast<int>(k), row, iBegin, iEnd);
      }
    }
  });
}

Box wholeGrid(const GridSpec& s) {
  return {{0, 0, 0}, {s.nx, s.ny, s.nz}};
}

// The occupied voxels' bounding box grown by one voxel within the grid; empty (hi = lo) when
// nothing is occupied. With `columns`, also each row's columns that hold an occupied voxel.
Box occupiedBox(const VoxelGrid& grid, Columns* columns = nullptr) {
  const GridSpec& s = grid.spec;
  cv::Vec3i lo(s.nx, s.ny, s.nz), hi(0, 0, 0);
  if (columns != nullptr) {
    columns->begin.assign(static_cast<std::size_t>(s.ny), s.nx);
    columns->end.assign(static_cast<std::size_t>(s.ny), 0);
  }
  for (int k = 0; k < s.nz; ++k)
    for (int j = 0; j < s.ny; ++j) {
      const std::uint8_t* row = &grid.occupied[s.index(0, j, k)];
      const auto occupied = [](std::uint8_t v) { return v != 0; };
      const std::uint8_t* first = std::find_if(row, row + s.nx, occupied);
      if (first == row + s.nx) continue;
      const auto last = std::find_if(std::make_reverse_iterator(row + s.nx),
                                     std::make_reverse_iterator(row), occupied);
      lo = {std::min(lo[0], static_cast<int>(first - row)), std::min(lo[1], j), std::min(lo[2], k)};
      hi = {std::max(hi[0], static_cast<int>(last.base() - row)), std::max(hi[1], j + 1),
            std::max(hi[2], k + 1)};
      if (columns != nullptr) {
        int& begin = columns->begin[static_cast<std::size_t>(j)];
        int& end = columns->end[static_cast<std::size_t>(j)];
        begin = std::min(begin, static_cast<int>(first - row));
        end = std::max(end, static_cast<int>(last.base() - row));
      }
    }
  if (hi[0] == 0) return {{0, 0, 0}, {0, 0, 0}};
  return {{std::max(lo[0] - 1, 0), std::max(lo[1] - 1, 0), std::max(lo[2] - 1, 0)},
          {std::min(hi[0] + 1, s.nx), std::min(hi[1] + 1, s.ny), std::min(hi[2] + 1, s.nz)}};
}

float toFloat(Squared squared) {
  return squared == kFar ? kNoVoxel : static_cast<float>(squared);
}

// An outside voxel's value: its distance to the nearest inside centre less half a voxel.
float outsideValue(Squared squared, float h) {
  return squared == kFar ? kNoVoxel : (std::sqrt(static_cast<float>(squared)) - 0.5f) * h;
}

// `box` grown by `cells` on every side, within the grid.
Box grown(const Box& box, const GridSpec& s, int cells) {
  return {{std::max(box.lo[0] - cells, 0), std::max(box.lo[1] - cells, 0),
           std::max(box.lo[2] - cells, 0)},
          {std::min(box.hi[0] + cells, s.nx), std::min(box.hi[1] + cells, s.ny),
           std::min(box.hi[2] + cells, s.nz)}};
}

// The field over `outsideBox` (which holds every inside voxel), min(value, clamp), and `clamp`
// beyond it; then every inside voxel's negative distance to the outside. `limit` (squared
// voxels) must hold every outside value up to the clamp: a value over it becomes the clamp.
std::vector<float> fieldOver(const VoxelGrid& grid, const Box& occupied, const Columns& columns,
                             const Box& outsideBox, float clamp, Squared limit, int threads) {
  const GridSpec& s = grid.spec;
  const auto h = static_cast<float>(s.voxelSize);
  const float far = std::min(kNoVoxel, clamp);
  std::vector<float> field(s.count(), far);
  transformBox(
      grid, outsideBox, 1, threads, limit, &columns,
      [&](int boxJ, int boxK, const Squared* row, int iBegin, int iEnd) {
        float* out =
            &field[s.index(outsideBox.lo[0], outsideBox.lo[1] + boxJ, outsideBox.lo[2] + boxK)];
        for (int i = iBegin; i < iEnd; ++i)
          out[i] = row[i] > limit ? far : std::min(outsideValue(row[i], h), clamp);
      });
  // Only inside voxels need their distance to the outside, and each has a nearest outside voxel
  // in the occupied bounding box grown by one voxel (clamping any other onto that box's border
  // layer, which is outside, brings it no farther): the transform runs on that box alone.
  if (occupied.count() == 0) return field;  // nothing inside
  transformBox<true>(
      grid, occupied, 0, threads, kNoLimit, nullptr,
      [&](int boxJ, int boxK, const Squared* row, int /*iBegin*/, int /*iEnd*/) {
        const int j = occupied.lo[1] + boxJ, k = occupied.lo[2] + boxK;
        for (int i = occupied.lo[0]; i < occupied.hi[0]; ++i) {
          const std::size_t n = s.index(i, j, k);
          if (!grid.occupied[n]) continue;
          // Beyond the grid counts as outside: an inside voxel is at most its distance to the
          // border plus one from an outside centre.
          const int border = 1 + std::min({i, j, k, s.nx - 1 - i, s.ny - 1 - j, s.nz - 1 - k});
          const auto squared = static_cast<float>(row[i - occupied.lo[0]]);
          field[n] = -(std::min(std::sqrt(squared), static_cast<float>(border)) - 0.5f) * h;
        }
      });
  return field;
}

}  // namespace

std::vector<float> squaredDistanceTo(const VoxelGrid& grid, std::uint8_t target, int threads) {
  const GridSpec& s = grid.spec;
  std::vector<float> d(s.count(), kNoVoxel);
  transformBox(grid, wholeGrid(s), target, threads, kNoLimit, nullptr,
               [&](int j, int k, const Squared* row, int iBegin, int iEnd) {
                 std::transform(row + iBegin, row + iEnd, &d[s.index(iBegin, j, k)], toFloat);
               });
  return d;
}

std::vector<float> signedDistanceField(const VoxelGrid& grid, int threads) {
  Columns columns;
  const Box occupied = occupiedBox(grid, &columns);
  return fieldOver(grid, occupied, columns, wholeGrid(grid.spec),
                   std::numeric_limits<float>::infinity(), kNoLimit, threads);
}

std::vector<float> signedDistanceFieldInBand(const VoxelGrid& grid, double band, int threads) {
  assert(band >= 0);  // NaN and negative bands are the caller's bug
  const GridSpec& s = grid.spec;
  Columns columns;
  const Box occupied = occupiedBox(grid, &columns);
  if (occupied.count() == 0) return std::vector<float>(s.count(), kNoVoxel);  // no surface
  const auto clamp = static_cast<float>(band);
  if (!(band < (s.nx + s.ny + s.nz) * s.voxelSize))  // the band holds the whole grid
    return fieldOver(grid, occupied, columns, wholeGrid(s), clamp, kNoLimit, threads);
  // A voxel beyond the occupied box (already grown by one) grown by `cells` is, along one axis,
  // over `cells` + 1 voxels from every inside centre: its value is over (cells + 1/2) voxels,
  // beyond the band. Inside the grown box the transform is exact: it holds every inside voxel.
  // Within it, a value up to the band is a squared distance up to (band / h + 1/2)^2 voxels^2:
  // the limit is that with a voxel to spare for the float rounding.
  const double cells = band / s.voxelSize;
  const auto limit = static_cast<Squared>(std::floor((cells + 1.5) * (cells + 1.5)));
  return fieldOver(grid, occupied, columns, grown(occupied, s, static_cast<int>(std::ceil(cells))),
                   clamp, limit, threads);
}

double fieldBandFor(double reach, const GridSpec& spec) {
  return reach + 2 * std::sqrt(3.0) * spec.voxelSize;
}

}  // namespace vrflow::camera
