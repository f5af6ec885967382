#include "node_coupling.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace vrflow::fluid::detail {
namespace {

/// Linear interpolation along one axis of `count` samples at index coordinate g: the two
/// samples and the weight of the second (clamped to the ends).
struct Axis {
  int i0 = 0, i1 = 0;
  double t = 0.0;
};

Axis axisAt(double g, int count) {
  if (count <= 1) return {};
  const int i0 = std::clamp(static_cast<int>(std::floor(g)), 0, count - 2);
  return {i0, i0 + 1, std::clamp(g - i0, 0.0, 1.0)};
}

double weightOf(const Axis& axis, int bit) {
  return bit ? axis.t : 1.0 - axis.t;
}
int indexOf(const Axis& axis, int bit) {
  return bit ? axis.i1 : axis.i0;
}

/// The columns' stencil: cell centres in x and z.
void columnAxes(const Grid& g, const PointMass& node, Axis& x, Axis& z) {
  x = axisAt((node.position[0] - g.ox) / g.h - 0.5, g.nx);
  z = axisAt((node.position[2] - g.oz) / g.h - 0.5, g.nz);
}

/// The faces' stencil of component a.
void faceAxes(const Grid& g, const PointMass& node, int a, Axis* axes) {
  const double o[3] = {g.ox, g.oy, g.oz};
  for (int d = 0; d < 3; ++d) {
    const double shift = d == a ? 0.0 : 0.5;
    axes[d] =
        axisAt((node.position[static_cast<std::size_t>(d)] - o[d]) / g.h - shift, g.fdim(a, d));
  }
}

/// Slot of face `f` (0..7, bits x, y, z) of component a: its velocity, then its flag.
int velocitySlot(int a, int f) {
  return kNodeColumns + 2 * (a * kNodeFaces + f);
}

/// The level (y) of the liquid in column (i, k) in the window of cells around the node's
/// sphere: the window's bottom plus, per cell, how full it is. A cell counts full when liquid
/// covers it (the cell above is liquid, or counts full itself and is not air); a liquid cell
/// with anything else above it counts its particles (min(1, n / n0)); air and uncovered body
/// cells count 0. The window starts a cell below the sphere, so a sphere with no liquid in it
/// gets a level under its lowest point.
double columnLevel(const NodeGridView& view, int i, int k, double y, double r) {
  const Grid& g = *view.grid;
  const auto& kind = *view.kind;
  const int lo = std::clamp(static_cast<int>(std::floor((y - r - g.oy) / g.h)) - 1, 0, g.ny - 1);
  const int hi = std::clamp(static_cast<int>(std::floor((y + r - g.oy) / g.h)) + 1, 0, g.ny - 1);
  bool covered = hi + 1 < g.ny && kind[g.cell(i, hi + 1, k)] == kLiquid;
  double filled = 0.0;
  for (int j = hi; j >= lo; --j) {
    const std::size_t c = g.cell(i, j, k);
    const auto here = kind[c];
    if (here != kAir && covered) {
      filled += 1.0;
    } else if (here == kLiquid) {
      filled += std::min(1.0, static_cast<double>((*view.particlesInCell)[c]) /
                                  static_cast<double>(view.particlesPerCell));
    }
    covered = here == kLiquid || (covered && here != kAir);
  }
  return g.oy + (lo + filled) * g.h;
}

}  // namespace

bool nodeInGrid(const Grid& g, const PointMass& node) {
  const double o[3] = {g.ox, g.oy, g.oz};
  const int n[3] = {g.nx, g.ny, g.nz};
  for (int d = 0; d < 3; ++d) {
    const double x = node.position[static_cast<std::size_t>(d)];
    if (!(x >= o[d] && x <= o[d] + n[d] * g.h)) return false;
  }
  return true;
}

void gatherNodeSlots(const NodeGridView& view, const PointMass& node, double* slots) {
  const Grid& g = *view.grid;
  if (!nodeInGrid(g, node)) return;
  Axis x, z;
  columnAxes(g, node, x, z);
  for (int c = 0; c < kNodeColumns; ++c) {
    const int k = indexOf(z, c >> 1);
    if (k < view.k0 || k >= view.k1) continue;
    slots[c] += columnLevel(view, indexOf(x, c & 1), k, node.position[1], node.radius);
  }
  const auto& kind = *view.kind;
  for (int a = 0; a < 3; ++a) {
    Axis axes[3];
    faceAxes(g, node, a, axes);
    const int cells[3] = {g.nx, g.ny, g.nz};
    for (int f = 0; f < kNodeFaces; ++f) {
      const int idx[3] = {indexOf(axes[0], f & 1), indexOf(axes[1], (f >> 1) & 1),
                          indexOf(axes[2], (f >> 2) & 1)};
      if (idx[2] < view.k0 || idx[2] >= view.kEnd[a]) continue;
      // The cells on either side of the face along a.
      int lo[3] = {idx[0], idx[1], idx[2]};
      lo[a] -= 1;
      const bool hiLiquid = idx[a] < cells[a] && kind[g.cell(idx[0], idx[1], idx[2])] == kLiquid;
      const bool loLiquid = lo[a] >= 0 && kind[g.cell(lo[0], lo[1], lo[2])] == kLiquid;
      if (!hiLiquid && !loLiquid) continue;
      double* slot = slots + velocitySlot(a, f);
      slot[0] += view.u[a][g.face(a, idx[0], idx[1], idx[2])];
      slot[1] += 1.0;
    }
  }
}

double nodeLiquidLevel(const Grid& g, const PointMass& node, const double* slots) {
  Axis x, z;
  columnAxes(g, node, x, z);
  double level = 0.0;
  for (int c = 0; c < kNodeColumns; ++c) {
    level += weightOf(x, c & 1) * weightOf(z, c >> 1) * slots[c];
  }
  return level;
}

double submergedVolume(double r, double y, double level) {
  const double d = std::clamp(level - (y - r), 0.0, 2.0 * r);  // depth of the sphere's bottom
  return std::numbers::pi * d * d * (3.0 * r - d) / 3.0;
}

BodyForce nodeForce(const Grid& g, const PointMass& node, const double* slots, double liquidDensity,
                    const msg::Vec3& gravity, double dt) {
  BodyForce out;
  out.id = node.id;
  out.index = node.index;
  out.point = node.position;
  out.duration = dt;
  if (!nodeInGrid(g, node)) return out;
  const double r = node.radius;
  const double below = submergedVolume(r, node.position[1], nodeLiquidLevel(g, node, slots));
  msg::Vec3 liquid = node.velocity;  // an axis with no face next to liquid: no drag along it
  int faces = 0;
  for (int a = 0; a < 3; ++a) {
    Axis axes[3];
    faceAxes(g, node, a, axes);
    double sum = 0.0, weight = 0.0;
    for (int f = 0; f < kNodeFaces; ++f) {
      const double* slot = slots + velocitySlot(a, f);
      if (slot[1] == 0.0) continue;
      const double w = weightOf(axes[0], f & 1) * weightOf(axes[1], (f >> 1) & 1) *
                       weightOf(axes[2], (f >> 2) & 1);
      sum += w * slot[0];
      weight += w;
      ++faces;
    }
    if (weight > 0.0) liquid[static_cast<std::size_t>(a)] = sum / weight;
  }
  out.cells = std::max(1, faces);
  if (below <= 0.0) return out;  // dry: exactly zero
  msg::Vec3 relative{};
  double speed2 = 0.0;
  for (std::size_t a = 0; a < 3; ++a) {
    relative[a] = node.velocity[a] - liquid[a];
    speed2 += relative[a] * relative[a];
  }
  // The submerged part's frontal area: across y the largest horizontal section below the level
  // (the waterline disc, the equator once half under), along x and z the circular segment the
  // cap shows from the side.
  const double d =
      std::clamp(nodeLiquidLevel(g, node, slots) - (node.position[1] - r), 0.0, 2.0 * r);
  const double disc = std::numbers::pi * (d < r ? d * (2.0 * r - d) : r * r);
  const double c = std::clamp((r - d) / r, -1.0, 1.0);
  const double segment = r * r * (std::acos(c) - c * std::sqrt(1.0 - c * c));
  const double speed = std::sqrt(speed2);
  for (std::size_t a = 0; a < 3; ++a) {
    const double area = a == 1 ? disc : segment;
    const double k = 0.5 * liquidDensity * kSphereDragCoefficient * area * speed;
    const double implicitK = k / (1.0 + k * dt / node.mass);
    out.force[a] = -liquidDensity * below * gravity[a] - implicitK * relative[a];
  }
  return out;
}

void applyNodeReaction(const NodeGridView& view, const PointMass& node, const double* slots,
                       const BodyForce& force, double liquidDensity, double dt,
                       std::vector<double>* u) {
  const Grid& g = *view.grid;
  if (force.cells == 0) return;
  const double faceMass = liquidDensity * g.h * g.h * g.h;
  for (int a = 0; a < 3; ++a) {
    const double impulse = force.force[static_cast<std::size_t>(a)] * dt;
    if (impulse == 0.0) continue;
    Axis axes[3];
    faceAxes(g, node, a, axes);
    double w[kNodeFaces];
    double total = 0.0;
    for (int f = 0; f < kNodeFaces; ++f) {
      w[f] = slots[velocitySlot(a, f) + 1] == 0.0
                 ? 0.0
                 : weightOf(axes[0], f & 1) * weightOf(axes[1], (f >> 1) & 1) *
                       weightOf(axes[2], (f >> 2) & 1);
      total += w[f];
    }
    if (total <= 0.0) continue;  // no liquid face around: the impulse has nowhere to go
    for (int f = 0; f < kNodeFaces; ++f) {
      const int idx[3] = {indexOf(axes[0], f & 1), indexOf(axes[1], (f >> 1) & 1),
                          indexOf(axes[2], (f >> 2) & 1)};
      if (w[f] == 0.0 || idx[2] < view.k0 || idx[2] >= view.kEnd[a]) continue;
      u[a][g.face(a, idx[0], idx[1], idx[2])] -= impulse * (w[f] / total) / faceMass;
    }
  }
}

}  // namespace vrflow::fluid::detail
