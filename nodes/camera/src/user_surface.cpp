#include "vrflow/camera/user_surface.hpp"

#include <algorithm>
#include <cmath>

namespace vrflow::camera {
namespace {

// Trilinear weights of world point p in a grid of cell centres: the lower cell and the fractions,
// clamped to the grid (a point beyond it takes the border's values).
struct Corner {
  std::array<std::size_t, 3> cell{};
  std::array<double, 3> fraction{};
};

Corner cornerOf(const UserSurface& u, const msg::Vec3& p) {
  Corner c;
  for (int a = 0; a < 3; ++a) {
    const double last = static_cast<double>(u.dims[a]) - 1.0;
    const double g = std::clamp((p[a] - u.origin[a]) / u.spacing, 0.0, last);
    const double lower = std::min(std::floor(g), std::max(last - 1.0, 0.0));
    c.cell[a] = static_cast<std::size_t>(lower);
    c.fraction[a] = g - lower;
  }
  return c;
}

// Trilinear interpolation of component `k` of `field` (`stride` floats per cell).
double sample(const UserSurface& u, const std::vector<float>& field, std::size_t stride,
              std::size_t k, const Corner& c) {
  const std::size_t nx = u.dims[0], ny = u.dims[1];
  const std::array<std::size_t, 3> step{u.dims[0] > 1 ? 1u : 0u, u.dims[1] > 1 ? 1u : 0u,
                                        u.dims[2] > 1 ? 1u : 0u};
  double value = 0;
  for (std::size_t corner = 0; corner < 8; ++corner) {
    double w = 1;
    std::array<std::size_t, 3> at = c.cell;
    for (std::size_t a = 0; a < 3; ++a) {
      const bool upper = ((corner >> a) & 1u) != 0;
      w *= upper ? c.fraction[a] : 1.0 - c.fraction[a];
      if (upper) at[a] += step[a];
    }
    if (w == 0) continue;
    value += w * field[((at[2] * ny + at[1]) * nx + at[0]) * stride + k];
  }
  return value;
}

// Distance from p to the box of the grid's cell centres (0 inside it).
double outsideBy(const UserSurface& u, const msg::Vec3& p) {
  double squared = 0;
  for (int a = 0; a < 3; ++a) {
    const double hi = u.origin[a] + (static_cast<double>(u.dims[a]) - 1.0) * u.spacing;
    const double d = std::max({u.origin[a] - p[a], p[a] - hi, 0.0});
    squared += d * d;
  }
  return std::sqrt(squared);
}

}  // namespace

bool UserSurface::ready() const {
  const std::size_t cells = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  return cells > 0 && spacing > 0 && sdf.size() == cells;
}

double UserSurface::distance(const msg::Vec3& p) const {
  if (!ready()) return 1e30;
  return sample(*this, sdf, 1, 0, cornerOf(*this, p)) + outsideBy(*this, p);
}

msg::Vec3 UserSurface::normal(const msg::Vec3& p) const {
  if (!ready()) return {};
  return unitGradient([this](const msg::Vec3& q) { return distance(q); }, p, 0.5 * spacing);
}

msg::Vec3 UserSurface::velocityAt(const msg::Vec3& p) const {
  const std::size_t cells = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  if (!ready() || velocity.size() != 3 * cells || outsideBy(*this, p) > 0) return {};
  const Corner c = cornerOf(*this, p);
  return {sample(*this, velocity, 3, 0, c), sample(*this, velocity, 3, 1, c),
          sample(*this, velocity, 3, 2, c)};
}

}  // namespace vrflow::camera
