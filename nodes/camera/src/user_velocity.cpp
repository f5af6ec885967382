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

// Box average of radius r along axis `axis` (stride between neighbours, n cells on the axis).
void boxAlong(std::vector<double>& values, const GridSpec& s, int axis, int r) {
  const std::array<int, 3> n{s.nx, s.ny, s.nz};
  const std::array<std::size_t, 3> stride{1, static_cast<std::size_t>(s.nx),
                                          static_cast<std::size_t>(s.nx) * s.ny};
  std::vector<double> line(static_cast<std::size_t>(n[axis]));
  const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
  for (int b = 0; b < n[w]; ++b) {
    for (int a = 0; a < n[u]; ++a) {
      const std::size_t start = a * stride[u] + b * stride[w];
      for (int i = 0; i < n[axis]; ++i) line[i] = values[start + i * stride[axis]];
      for (int i = 0; i < n[axis]; ++i) {
        const int lo = std::max(i - r, 0), hi = std::min(i + r, n[axis] - 1);
        double sum = 0;
        for (int j = lo; j <= hi; ++j) sum += line[j];
        values[start + i * stride[axis]] = sum / (hi - lo + 1);
      }
    }
  }
}

}  // namespace

std::vector<float> surfaceVelocity(const GridSpec& spec, const std::vector<float>& sdfBefore,
                                   const std::vector<float>& sdfNow, double dt,
                                   const SurfaceVelocitySettings& settings) {
  const std::size_t count = spec.count();
  std::vector<float> velocity(3 * count, 0.0f);
  if (!(dt > 0) || sdfBefore.size() != count || sdfNow.size() != count || !hasSurface(sdfBefore) ||
      !hasSurface(sdfNow))
    return velocity;
  std::vector<double> change(count);
  for (std::size_t c = 0; c < count; ++c)
    change[c] = static_cast<double>(sdfNow[c]) - static_cast<double>(sdfBefore[c]);
  if (settings.smoothing > 0)
    for (int axis = 0; axis < 3; ++axis) boxAlong(change, spec, axis, settings.smoothing);
  const std::array<int, 3> n{spec.nx, spec.ny, spec.nz};
  const double h = spec.voxelSize;
  for (int k = 0; k < spec.nz; ++k)
    for (int j = 0; j < spec.ny; ++j)
      for (int i = 0; i < spec.nx; ++i) {
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
        double speed = -change[c] / dt / std::sqrt(norm2);
        speed = std::clamp(speed, -settings.maxSpeed, settings.maxSpeed);
        const double scale = speed / std::sqrt(norm2);
        for (int a = 0; a < 3; ++a) velocity[3 * c + a] = static_cast<float>(g[a] * scale);
      }
  return velocity;
}

}  // namespace vrflow::camera
