#include "vrflow/massspring/solver.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
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

namespace {

double springLength(const Net& net, const Spring& s) {
  const auto a = net.position(s.a), b = net.position(s.b);
  return std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                   (b[2] - a[2]) * (b[2] - a[2]));
}

/// length / (maxStretch * restLength), computed as maxConstraintRatio does.
double constraintRatio(const Net& net, const Spring& s) {
  return springLength(net, s) / (s.maxStretch * s.restLength);
}

/// The local back-off: the nodes of every spring still beyond its limit go back to `feasible`
/// (their motion of this sub-step is cut), and so do, round after round, the nodes of springs
/// that this back-off stretched beyond their limits, until every limit holds. A spring whose two
/// nodes went back is as it was in `feasible`, inside its limit, so the rounds end; the rest of
/// the net keeps its motion. The position change, divided by h, goes into the velocity.
void backOffLocally(Net& net, std::span<const double> feasible, double invH) {
  std::vector<std::uint8_t> back(net.nodeCount(), 0);
  auto moveBack = [&](std::uint32_t node) {
    if (back[node]) return false;
    back[node] = 1;
    for (std::size_t k = 3 * std::size_t{node}; k < 3 * std::size_t{node} + 3; ++k) {
      net.velocities[k] += (feasible[k] - net.positions[k]) * invH;
      net.positions[k] = feasible[k];
    }
    return true;
  };
  for (bool moved = true; moved;) {
    moved = false;
    for (const auto& s : net.springs) {
      if (s.maxStretch <= 0 || (back[s.a] && back[s.b]) || constraintRatio(net, s) <= 1.0) continue;
      const bool a = moveBack(s.a), b = moveBack(s.b);
      moved = moved || a || b;
    }
  }
}

/// A set of spring indices walked in index order, forward or backward, while members are added
/// ahead of the walk (a bit per spring).
class SweepSet {
 public:
  explicit SweepSet(std::size_t count) : bits_((count + 63) / 64, 0), count_(count) {}
  void insert(std::size_t i) { bits_[i / 64] |= std::uint64_t{1} << (i % 64); }
  void erase(std::size_t i) { bits_[i / 64] &= ~(std::uint64_t{1} << (i % 64)); }
  /// The first member at or after `from`; the count when none.
  std::size_t next(std::size_t from) const {
    std::size_t word = from / 64;
    if (word >= bits_.size()) return count_;
    std::uint64_t bits = bits_[word] & (~std::uint64_t{0} << (from % 64));
    while (bits == 0) {
      if (++word == bits_.size()) return count_;
      bits = bits_[word];
    }
    return 64 * word + static_cast<std::size_t>(std::countr_zero(bits));
  }
  /// The last member before `end`; the count when none.
  std::size_t previous(std::size_t end) const {
    if (end == 0) return count_;
    std::size_t word = (end - 1) / 64;
    std::uint64_t bits = bits_[word] & (~std::uint64_t{0} >> (63 - (end - 1) % 64));
    while (bits == 0) {
      if (word == 0) return count_;
      bits = bits_[--word];
    }
    return 64 * word + 63 - static_cast<std::size_t>(std::countl_zero(bits));
  }

 private:
  std::vector<std::uint64_t> bits_;
  std::size_t count_;
};

}  // namespace

double enforceMaxStretch(Net& net, double h, int maxIterations, std::span<const double> feasible,
                         std::span<double> multipliers) {
  bool any = false;
  for (const auto& s : net.springs) any = any || s.maxStretch > 0;
  if (!any) return 0.0;
  double* x = net.positions.data();
  double* v = net.velocities.data();
  const double invH = 1.0 / h;
  constexpr double kTolerance = 1e-9;
  constexpr double kSkip = (1 + 0.1 * kTolerance) * (1 + 0.1 * kTolerance);
  const std::size_t count = net.springs.size();
  std::vector<double> scratch;
  if (multipliers.size() != count) {
    scratch.assign(count, 0.0);
    multipliers = scratch;
  }
  // Each node's inverse mass (pinned: 0).
  std::vector<double> inverseMass(net.nodeCount());
  for (std::size_t i = 0; i < net.nodeCount(); ++i)
    inverseMass[i] = net.pinned[i] ? 0.0 : 1.0 / net.masses[i];
  // The springs a sweep visits: a spring found within its limit and pulling nothing stays so
  // until one of its nodes moves, so it leaves the set and comes back when a correction moves one
  // of its nodes (the limited springs of each node, CSR). The sweeps do what they did over every
  // spring, without reading the others.
  std::vector<std::size_t> start(net.nodeCount() + 1, 0), limited;
  for (const auto& s : net.springs) {
    if (s.maxStretch <= 0) continue;
    ++start[s.a + 1];
    ++start[s.b + 1];
  }
  for (std::size_t i = 0; i < net.nodeCount(); ++i) start[i + 1] += start[i];
  limited.resize(start.back());
  SweepSet visit(count);
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t index = 0; index < count; ++index) {
      const auto& s = net.springs[index];
      if (s.maxStretch <= 0) continue;
      limited[fill[s.a]++] = index;
      limited[fill[s.b]++] = index;
      visit.insert(index);
    }
  }
  // Moves the ends of spring s together by `amount` (inverse-mass weighted, along d of length
  // `length`; negative moves them apart), the change divided by h going into the velocities.
  auto apply = [&](const Spring& s, double wa, double wb, double d0, double d1, double d2,
                   double length, double amount) {
    const std::size_t a = 3 * std::size_t{s.a}, b = 3 * std::size_t{s.b};
    const double scale = amount / length;
    addOpposite(x, a, b, wa * scale, wb * scale, d0, d1, d2);
    addOpposite(v, a, b, wa * scale, wb * scale, d0, d1, d2, invH);
    for (const std::uint32_t node : {s.a, s.b})
      for (std::size_t k = start[node]; k < start[node + 1]; ++k) visit.insert(limited[k]);
  };
  // Warm start: the corrections that held the net at the end of the last sub-step are applied
  // again first (a net hanging at its limits needs about the same ones every sub-step).
  for (std::size_t index = 0; index < count; ++index) {
    const auto& s = net.springs[index];
    if (s.maxStretch <= 0 || !(multipliers[index] > 0) || !std::isfinite(multipliers[index])) {
      multipliers[index] = 0;
      continue;
    }
    const std::size_t a = 3 * std::size_t{s.a}, b = 3 * std::size_t{s.b};
    const double wa = inverseMass[s.a], wb = inverseMass[s.b];
    const double d0 = x[b] - x[a], d1 = x[b + 1] - x[a + 1], d2 = x[b + 2] - x[a + 2];
    const double length = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
    if (wa + wb == 0 || length < 1e-12) {
      multipliers[index] = 0;
      continue;
    }
    apply(s, wa, wb, d0, d1, d2, length, multipliers[index]);
  }
  // Projected Gauss-Seidel on the inequalities length <= limit: each spring's correction is
  // accumulated in its multiplier (mass-weighted length, >= 0); a spring whose multiplier would
  // turn negative is let go (its ends move apart to where they would be without it).
  bool moving = true;
  for (int iteration = 0; iteration < maxIterations && moving; ++iteration) {
    moving = false;
    // Symmetric Gauss-Seidel: forward, then backward sweeps (corrections travel both ways).
    const bool forward = iteration % 2 == 0;
    for (std::size_t index = forward ? visit.next(0) : visit.previous(count); index < count;
         index = forward ? visit.next(index + 1) : visit.previous(index)) {
      const auto& s = net.springs[index];
      const std::size_t a = 3 * std::size_t{s.a}, b = 3 * std::size_t{s.b};
      const double limit = s.maxStretch * s.restLength;
      const double d0 = x[b] - x[a], d1 = x[b + 1] - x[a + 1], d2 = x[b + 2] - x[a + 2];
      const double squared = d0 * d0 + d1 * d1 + d2 * d2;
      if (multipliers[index] == 0 && squared <= limit * limit * kSkip) {
        visit.erase(index);
        continue;
      }
      const double wa = inverseMass[s.a], wb = inverseMass[s.b];
      const double length = std::sqrt(squared);
      if (wa + wb == 0 || length < 1e-12) continue;
      // Aim slightly inside the limit so rounding leaves the length at or below it.
      const double error = length - limit * (1 - 0.5 * kTolerance);
      const double total = std::max(0.0, multipliers[index] + error / (wa + wb));
      const double amount = total - multipliers[index];
      if (amount == 0) continue;
      multipliers[index] = total;
      apply(s, wa, wb, d0, d1, d2, length, amount);
      if (std::abs(amount) * (wa + wb) > 0.5 * kTolerance * limit) moving = true;
    }
  }
  if (maxConstraintRatio(net) > 1.0 && feasible.size() == net.positions.size())
    backOffLocally(net, feasible, invH);
  return maxConstraintRatio(net);
}

double step(Net& net, std::span<const double> externalForces, const StepOptions& options,
            const UserColliders* users) {
  const std::size_t n = net.nodeCount();
  const double h = options.dt / options.substeps;
  std::vector<double> forces(3 * n);
  std::vector<double> start, before;
  const bool colliding = users && !users->users.empty();
  auto& warm = options.warmStart;
  if (warm.size() != net.springs.size()) warm.assign(net.springs.size(), 0.0);
  const std::span<double> multipliers = warm;
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
    if (colliding) before = net.positions;
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
    // The users hold the nodes they touch before the springs' limits are projected.
    if (colliding)
      collideWithUsers(net, before, *users, static_cast<double>(sub + 1) / options.substeps);
    worst = enforceMaxStretch(net, h, options.constraintIterations, start, multipliers);
  }
  return worst;
}

double fastestSpringFrequency(const Net& net, int iterations) {
  const std::size_t n = net.nodeCount();
  // Power iteration on A = M^-1/2 K M^-1/2 (symmetric, positive semi-definite), pinned nodes
  // held at zero. The start vector is fixed and irregular so that it is orthogonal to no mode.
  std::vector<double> scale(3 * n, 0.0), v(3 * n, 0.0), w(3 * n), z(3 * n);
  std::uint64_t seed = 0x9e3779b97f4a7c15ULL;
  for (std::size_t i = 0; i < 3 * n; ++i) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    if (net.pinned[i / 3]) continue;
    scale[i] = 1.0 / std::sqrt(net.masses[i / 3]);
    v[i] = static_cast<double>(seed >> 11) * 0x1.0p-53 - 0.5;
  }
  double best = 0.0;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    double norm = 0;
    for (double x : v) norm += x * x;
    if (!(norm > 0) || !std::isfinite(norm)) break;
    for (std::size_t i = 0; i < 3 * n; ++i) w[i] = v[i] * scale[i];
    std::fill(z.begin(), z.end(), 0.0);
    for (const auto& s : net.springs) {
      const std::size_t a = 3 * std::size_t{s.a}, b = 3 * std::size_t{s.b};
      const double d0 = net.positions[b] - net.positions[a],
                   d1 = net.positions[b + 1] - net.positions[a + 1],
                   d2 = net.positions[b + 2] - net.positions[a + 2];
      const double length = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
      if (length < 1e-12 || s.stiffness <= 0) continue;
      const double u0 = d0 / length, u1 = d1 / length, u2 = d2 / length;
      const double across = s.stiffness * std::max(0.0, 1.0 - s.restLength / length);
      const double e0 = w[b] - w[a], e1 = w[b + 1] - w[a + 1], e2 = w[b + 2] - w[a + 2];
      const double along = (s.stiffness - across) * (u0 * e0 + u1 * e1 + u2 * e2);
      // K_s e = k u u^T e + across (I - u u^T) e = (k - across) (u.e) u + across e.
      addOpposite(z.data(), b, a, 1.0, 1.0, along * u0 + across * e0, along * u1 + across * e1,
                  along * u2 + across * e2);
    }
    double quotient = 0, next = 0;
    for (std::size_t i = 0; i < 3 * n; ++i) {
      z[i] *= scale[i];
      quotient += v[i] * z[i];
      next += z[i] * z[i];
    }
    best = std::max(best, quotient / norm);
    if (!(next > 0)) break;
    const double inv = 1.0 / std::sqrt(next);
    for (std::size_t i = 0; i < 3 * n; ++i) v[i] = z[i] * inv;
  }
  return std::sqrt(best);
}

double kineticEnergy(const Net& net) {
  double e = 0;
  for (std::size_t i = 0; i < net.nodeCount(); ++i) {
    const auto v = net.velocity(i);
    e += 0.5 * net.masses[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  return e;
}

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
