#include "vrflow/massspring/solver.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace vrflow::massspring {
namespace {

/// Adds wa * (d0, d1, d2) * scale to the three values of node a and subtracts
/// wb * (d0, d1, d2) * scale from those of node b (a, b: the nodes' first indices); scale 1
/// leaves the products exact, as written out.
void addOpposite(double* values, std::size_t a, std::size_t b, double wa, double wb, double d0,
                 double d1, double d2, double scale = 1.0) {
  values[a] += wa * d0 * scale;
  values[a + 1] += wa * d1 * scale;
  values[a + 2] += wa * d2 * scale;
  values[b] -= wb * d0 * scale;
  values[b + 1] -= wb * d1 * scale;
  values[b + 2] -= wb * d2 * scale;
}

}  // namespace

Status validateStepOptions(const StepOptions& o) {
  if (!(o.dt > 0) || !std::isfinite(o.dt))
    return makeError("mass-spring step: dt must be finite and > 0");
  if (o.substeps < 1 || o.substeps > 100000)
    return makeError("mass-spring step: substeps must be in [1, 100000]");
  if (o.constraintIterations < 0)
    return makeError("mass-spring step: constraint iterations must be >= 0");
  for (double g : o.gravity) {
    if (!std::isfinite(g)) return makeError("mass-spring step: gravity must be finite");
  }
  return {};
}

void addSpringForces(const Net& net, std::span<const Spring> springs, std::span<double> forces) {
  const double* x = net.positions.data();
  const double* v = net.velocities.data();
  for (const auto& s : springs) {
    const std::size_t a = 3 * std::size_t{s.a}, b = 3 * std::size_t{s.b};
    const double d0 = x[b] - x[a], d1 = x[b + 1] - x[a + 1], d2 = x[b + 2] - x[a + 2];
    const double length = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
    if (length < 1e-12) continue;
    const double inv = 1.0 / length;
    const double u0 = d0 * inv, u1 = d1 * inv, u2 = d2 * inv;
    const double relSpeed =
        (v[b] - v[a]) * u0 + (v[b + 1] - v[a + 1]) * u1 + (v[b + 2] - v[a + 2]) * u2;
    const double magnitude = s.stiffness * (length - s.restLength) + s.damping * relSpeed;
    addOpposite(forces.data(), a, b, magnitude, magnitude, u0, u1, u2);
  }
}

void addSpringForces(const Net& net, std::span<double> forces) {
  addSpringForces(net, net.springs, forces);
}

double feasibleFraction(const Net& net, std::span<const double> from, std::span<const double> to) {
  constexpr double kTolerance = 1e-9;
  // Each spring's constraint holds on an interval of t that contains 0, so the smallest root over
  // the springs is safe.
  double t = 1.0;
  for (const auto& s : net.springs) {
    if (s.maxStretch <= 0) continue;
    const std::size_t a = 3 * std::size_t{s.a}, b = 3 * std::size_t{s.b};
    const double limit = s.maxStretch * s.restLength * (1 - 0.5 * kTolerance);
    double aa = 0, bb = 0, cc = -limit * limit, now = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      const double d = from[b + k] - from[a + k];
      const double e = (to[b + k] - to[a + k]) - d;
      aa += e * e;
      bb += d * e;
      cc += d * d;
      now += (to[b + k] - to[a + k]) * (to[b + k] - to[a + k]);
    }
    if (now <= limit * limit || aa <= 0) continue;
    if (cc >= 0) {
      t = 0;  // the start was not inside this limit: stay there
      continue;
    }
    t = std::min(t, (-bb + std::sqrt(std::max(0.0, bb * bb - aa * cc))) / aa);
  }
  return t;
}

double enforceMaxStretch(Net& net, double h, int maxIterations, std::span<const double> feasible) {
  bool any = false;
  for (const auto& s : net.springs) any = any || s.maxStretch > 0;
  if (!any) return 0.0;
  double* x = net.positions.data();
  double* v = net.velocities.data();
  const double invH = 1.0 / h;
  constexpr double kTolerance = 1e-9;
  constexpr double kSkip = (1 + 0.1 * kTolerance) * (1 + 0.1 * kTolerance);
  constexpr double kViolated = (1 + kTolerance) * (1 + kTolerance);
  const std::size_t count = net.springs.size();
  bool violated = true;
  for (int iteration = 0; iteration < maxIterations && violated; ++iteration) {
    violated = false;
    // Symmetric Gauss-Seidel: forward, then backward sweeps (corrections travel both ways).
    for (std::size_t index = 0; index < count; ++index) {
      const auto& s = net.springs[iteration % 2 == 0 ? index : count - 1 - index];
      if (s.maxStretch <= 0) continue;
      const std::size_t a = 3 * std::size_t{s.a}, b = 3 * std::size_t{s.b};
      const double limit = s.maxStretch * s.restLength;
      const double d0 = x[b] - x[a], d1 = x[b + 1] - x[a + 1], d2 = x[b + 2] - x[a + 2];
      const double squared = d0 * d0 + d1 * d1 + d2 * d2;
      if (squared <= limit * limit * kSkip) continue;
      if (squared > limit * limit * kViolated) violated = true;
      const double length = std::sqrt(squared);
      const double wa = net.pinned[s.a] ? 0.0 : 1.0 / net.masses[s.a];
      const double wb = net.pinned[s.b] ? 0.0 : 1.0 / net.masses[s.b];
      if (wa + wb == 0) continue;
      // Aim slightly inside the limit so rounding leaves the length at or below it. The
      // position change, divided by h, goes into the velocity.
      const double excess = (length - limit * (1 - 0.5 * kTolerance)) / (length * (wa + wb));
      const double ca = wa * excess, cb = wb * excess;
      addOpposite(x, a, b, ca, cb, d0, d1, d2);
      addOpposite(v, a, b, ca, cb, d0, d1, d2, invH);
    }
  }
  if (maxConstraintRatio(net) > 1.0 && feasible.size() == net.positions.size()) {
    // Not converged: back off along the segment from the feasible positions to these, to the
    // largest fraction at which every limited spring holds.
    double t = feasibleFraction(net, feasible, net.positions);
    t = std::max(0.0, t * (1 - 1e-12));
    for (std::size_t i = 0; i < net.positions.size(); ++i) {
      const double backed = feasible[i] + t * (x[i] - feasible[i]);
      v[i] += (backed - x[i]) * invH;
      x[i] = backed;
    }
  }
  return maxConstraintRatio(net);
}

double step(Net& net, std::span<const double> externalForces, const StepOptions& options) {
  const std::size_t n = net.nodeCount();
  const double h = options.dt / options.substeps;
  std::vector<double> forces(3 * n);
  std::vector<double> start;
  double worst = maxConstraintRatio(net);
  for (int sub = 0; sub < options.substeps; ++sub) {
    for (std::size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) {
        forces[3 * i + k] = (externalForces.empty() ? 0.0 : externalForces[3 * i + k]) +
                            net.masses[i] * options.gravity[k];
      }
    }
    if (options.internalSprings) addSpringForces(net, forces);
    // The start of the sub-step, a fallback inside every limit when it was inside before.
    if (worst <= 1.0)
      start = net.positions;
    else
      start.clear();
    for (std::size_t i = 0; i < n; ++i) {
      if (net.pinned[i]) {
        for (int k = 0; k < 3; ++k) net.velocities[3 * i + k] = 0.0;
        continue;
      }
      const double invMass = 1.0 / net.masses[i];
      for (int k = 0; k < 3; ++k) {
        net.velocities[3 * i + k] += h * forces[3 * i + k] * invMass;
        net.positions[3 * i + k] += h * net.velocities[3 * i + k];
      }
    }
    worst = enforceMaxStretch(net, h, options.constraintIterations, start);
  }
  return worst;
}

double kineticEnergy(const Net& net) {
  double e = 0;
  for (std::size_t i = 0; i < net.nodeCount(); ++i) {
    const auto v = net.velocity(i);
    e += 0.5 * net.masses[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  return e;
}

namespace {
double springLength(const Net& net, const Spring& s) {
  const auto a = net.position(s.a), b = net.position(s.b);
  return std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                   (b[2] - a[2]) * (b[2] - a[2]));
}
}  // namespace

double elasticEnergy(const Net& net) {
  double e = 0;
  for (const auto& s : net.springs) {
    const double stretch = springLength(net, s) - s.restLength;
    e += 0.5 * s.stiffness * stretch * stretch;
  }
  return e;
}

double gravityEnergy(const Net& net, const msg::Vec3& gravity) {
  double e = 0;
  for (std::size_t i = 0; i < net.nodeCount(); ++i) {
    const auto x = net.position(i);
    e -= net.masses[i] * (gravity[0] * x[0] + gravity[1] * x[1] + gravity[2] * x[2]);
  }
  return e;
}

double maxStretchRatio(const Net& net) {
  double worst = 0;
  for (const auto& s : net.springs) worst = std::max(worst, springLength(net, s) / s.restLength);
  return worst;
}

double maxConstraintRatio(const Net& net) {
  double worst = 0;
  for (const auto& s : net.springs) {
    if (s.maxStretch > 0)
      worst = std::max(worst, springLength(net, s) / (s.maxStretch * s.restLength));
  }
  return worst;
}

}  // namespace vrflow::massspring
