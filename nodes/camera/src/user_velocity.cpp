#include "vrflow/camera/user_velocity.hpp"

#include <algorithm>
#include <cmath>

#include "vrflow/camera/distance_field.hpp"

namespace vrflow::camera {
namespace {

// A field with no surface holds distances near sqrt(kNoVoxel): nothing to estimate from.
bool hasSurface(const std::vector<float>& sdf) {
  const float none = 0.5f * std::sqrt(kNoVoxel);
  return !sdf.empty() &&
         std::all_of(sdf.begin(), sdf.end(), [none](float d) { return std::abs(d) < none; });
}

// Box average of radius r along axis `axis` of `values`, a block of n[0] x n[1] x n[2] cells (x
// fastest); the window is clamped to the block. The block is walked as slabs [outer][axis][inner]
// whose inner rows are contiguous, so that the y and z passes read memory in order, as the x pass
// does; each cell's sum is taken in the same order whatever the axis.
void boxAlong(std::vector<double>& values, const std::array<int, 3>& n, int axis, int r) {
  const std::size_t inner = axis == 0   ? 1
                            : axis == 1 ? static_cast<std::size_t>(n[0])
                                        : static_cast<std::size_t>(n[0]) * n[1];
  const int length = n[axis];
  const std::size_t slab = inner * static_cast<std::size_t>(length);
  std::vector<double> copy(slab);
  for (std::size_t start = 0; start + slab <= values.size(); start += slab) {
    double* base = values.data() + start;
    std::copy(base, base + slab, copy.begin());
    for (int i = 0; i < length; ++i) {
      const int lo = std::max(i - r, 0), hi = std::min(i + r, length - 1);
      double* out = base + static_cast<std::size_t>(i) * inner;
      std::fill(out, out + inner, 0.0);
      for (int j = lo; j <= hi; ++j) {
        const double* in = copy.data() + static_cast<std::size_t>(j) * inner;
        for (std::size_t e = 0; e < inner; ++e) out[e] += in[e];
      }
      const double cells = hi - lo + 1;
      for (std::size_t e = 0; e < inner; ++e) out[e] /= cells;
    }
  }
}

// The cells [lo, hi] (inclusive) of the box around every cell within `band` of the surface,
// widened by `margin` cells and clamped to the grid; lo > hi on an axis when no cell is.
struct CellBox {
  std::array<int, 3> lo{}, hi{};
  bool empty() const { return lo[0] > hi[0]; }
  std::array<int, 3> size() const {
    return {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1};
  }
};

CellBox bandBox(const GridSpec& spec, const std::vector<float>& sdf, double band, int margin) {
  CellBox box{{spec.nx, spec.ny, spec.nz}, {-1, -1, -1}};
  for (int k = 0; k < spec.nz; ++k)
    for (int j = 0; j < spec.ny; ++j) {
      const std::size_t row = spec.index(0, j, k);
      for (int i = 0; i < spec.nx; ++i) {
        if (std::abs(sdf[row + static_cast<std::size_t>(i)]) > band) continue;
        const std::array<int, 3> at{i, j, k};
        for (int a = 0; a < 3; ++a) {
          box.lo[a] = std::min(box.lo[a], at[a]);
          box.hi[a] = std::max(box.hi[a], at[a]);
        }
      }
    }
  if (box.lo[0] > box.hi[0]) return box;
  const std::array<int, 3> n{spec.nx, spec.ny, spec.nz};
  for (int a = 0; a < 3; ++a) {
    box.lo[a] = std::max(box.lo[a] - margin, 0);
    box.hi[a] = std::min(box.hi[a] + margin, n[a] - 1);
  }
  return box;
}

}  // namespace

std::vector<float> surfaceVelocity(const GridSpec& spec, const std::vector<float>& sdfBefore,
                                   const std::vector<float>& sdfNow, double dt,
                                   const SurfaceVelocitySettings& settings,
                                   SurfaceChangeHistory* history) {
  const std::size_t count = spec.count();
  std::vector<float> velocity(3 * count, 0.0f);
  if (!(dt > 0) || sdfBefore.size() != count || sdfNow.size() != count || !hasSurface(sdfBefore) ||
      !hasSurface(sdfNow)) {
    if (history != nullptr) history->clear();
    return velocity;
  }
  const bool average = settings.frames > 1 && history != nullptr;
  if (average) {
    // Exponential average over about `frames` frames, from zero, of every cell (a cell far from
    // the surface now may be near it later).
    if (history->size() != count) history->assign(count, 0.0f);
    const double weight = 1.0 / settings.frames;
    for (std::size_t c = 0; c < count; ++c) {
      const double change = static_cast<double>(sdfNow[c]) - static_cast<double>(sdfBefore[c]);
      (*history)[c] = static_cast<float>((*history)[c] + weight * (change - (*history)[c]));
    }
  }
  // Only the cells within the band get a velocity, and the box average of a cell reads cells up
  // to `smoothing` away: the change is needed in the band's box widened by that, not in the grid
  // (a user fills a small part of its volume). Inside that box every band cell's window is the
  // same as in the whole grid, so the values are too.
  const int r = std::max(settings.smoothing, 0);
  const CellBox box = bandBox(spec, sdfNow, settings.band, r);
  if (box.empty()) return velocity;
  const std::array<int, 3> m = box.size();
  std::vector<double> change(static_cast<std::size_t>(m[0]) * m[1] * m[2]);
  auto local = [&](int i, int j, int k) {
    return static_cast<std::size_t>(i - box.lo[0]) +
           static_cast<std::size_t>(m[0]) *
               (static_cast<std::size_t>(j - box.lo[1]) +
                static_cast<std::size_t>(m[1]) * static_cast<std::size_t>(k - box.lo[2]));
  };
  for (int k = box.lo[2]; k <= box.hi[2]; ++k)
    for (int j = box.lo[1]; j <= box.hi[1]; ++j)
      for (int i = box.lo[0]; i <= box.hi[0]; ++i) {
        const std::size_t c = spec.index(i, j, k);
        change[local(i, j, k)] =
            average ? static_cast<double>((*history)[c])
                    : static_cast<double>(sdfNow[c]) - static_cast<double>(sdfBefore[c]);
      }
  if (r > 0)
    for (int axis = 0; axis < 3; ++axis) boxAlong(change, m, axis, r);
  const std::array<int, 3> n{spec.nx, spec.ny, spec.nz};
  const double h = spec.voxelSize;
  for (int k = box.lo[2]; k <= box.hi[2]; ++k)
    for (int j = box.lo[1]; j <= box.hi[1]; ++j)
      for (int i = box.lo[0]; i <= box.hi[0]; ++i) {
        const std::size_t c = spec.index(i, j, k);
        if (std::abs(sdfNow[c]) > settings.band) continue;
        // Central differences of phi_now (one-sided at the grid's faces).
        const std::array<int, 3> at{i, j, k};
        double g[3], norm2 = 0;
        for (int a = 0; a < 3; ++a) {
          std::array<int, 3> lo = at, hi = at;
          lo[a] = std::max(at[a] - 1, 0);
          hi[a] = std::min(at[a] + 1, n[a] - 1);
          const double span = (hi[a] - lo[a]) * h;
          g[a] = span > 0 ? (sdfNow[spec.index(hi[0], hi[1], hi[2])] -
                             sdfNow[spec.index(lo[0], lo[1], lo[2])]) /
                                span
                          : 0.0;
          norm2 += g[a] * g[a];
        }
        if (norm2 < 0.25) continue;  // the medial axis: no normal to move along
        double speed = -change[local(i, j, k)] / dt / std::sqrt(norm2);
        speed = std::clamp(speed, -settings.maxSpeed, settings.maxSpeed);
        const double scale = speed / std::sqrt(norm2);
        for (int a = 0; a < 3; ++a) velocity[3 * c + a] = static_cast<float>(g[a] * scale);
      }
  return velocity;
}

}  // namespace vrflow::camera
