// The solver against analytic answers and invariants: oscillator period, maximum stretch,
// energy of an undamped net.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "paper_net.hpp"
#include "vrflow/massspring/solver.hpp"

namespace vrflow::massspring {
namespace {

// Node 0 pinned at the origin, node 1 of mass m on a spring of stiffness k along x.
Net oscillator(double m, double k, double rest, double x0) {
  Net net;
  net.positions = {0, 0, 0, rest + x0, 0, 0};
  net.velocities.assign(6, 0.0);
  net.masses = {1.0, m};
  net.pinned = {1, 0};
  net.springs = {{0, 1, rest, k, 0.0, 0.0}};
  return net;
}

// Period from the upward zero crossings of x - rest (linear interpolation between steps).
double measuredPeriod(double m, double k, const StepOptions& options, int steps) {
  Net net = oscillator(m, k, 1.0, 0.1);
  std::vector<double> crossings;
  double previous = net.positions[3] - 1.0;
  for (int s = 1; s <= steps; ++s) {
    step(net, {}, options);
    const double x = net.positions[3] - 1.0;
    if (previous < 0 && x >= 0)
      crossings.push_back(options.dt * (s - 1 + previous / (previous - x)));
    previous = x;
  }
  if (crossings.size() < 2) return 0;
  return (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

TEST(MassSpringPhysics, OscillatorPeriodWithinOnePercent) {
  const double m = 0.5, k = 200.0;
  const double expected = 2 * std::numbers::pi * std::sqrt(m / k);  // 0.3142 s
  StepOptions options;
  options.dt = 0.01;
  options.substeps = 10;
  const double period = measuredPeriod(m, k, options, 1000);  // 10 s, about 32 periods
  const double error = std::abs(period - expected) / expected;
  std::printf("oscillator: period %.6f s, expected %.6f s, relative error %.2e\n", period, expected,
              error);
  EXPECT_LT(error, 0.01);
  // The sub-steps matter: one step per outer step of 0.05 s (omega dt = 1) is visibly off.
  options.dt = 0.05;
  options.substeps = 1;
  const double coarse = measuredPeriod(m, k, options, 200);
  EXPECT_GT(std::abs(coarse - expected) / expected, 0.03) << coarse;
  options.substeps = 20;
  EXPECT_LT(std::abs(measuredPeriod(m, k, options, 200) - expected) / expected, 0.01);
}

TEST(MassSpringPhysics, MaximumStretchNeverExceededUnderHeavyLoad) {
  GridParams grid;
  grid.n = grid.m = 12;
  grid.spacing = 0.1;
  grid.mass = 1.0;
  grid.stiffness = 100.0;  // soft: the load alone would stretch springs far beyond 10 %
  grid.maxStretch = 1.1;
  auto net = generateGrid(grid);
  ASSERT_TRUE(net) << net.error().message;
  StepOptions options;
  options.dt = 0.01;
  options.substeps = 10;
  options.gravity = {0, -9.81, 0};
  std::vector<double> load(3 * net->nodeCount(), 0.0);
  for (std::size_t j = 5; j <= 7; ++j) {
    for (std::size_t i = 5; i <= 7; ++i)
      load[3 * (j * 12 + i) + 1] = -5.0;  // 45 N: 4.6 times the net's weight
  }
  double worst = 0, worstStretch = 0;
  for (int s = 0; s < 300; ++s) {
    step(*net, load, options);
    worst = std::max(worst, maxConstraintRatio(*net));
    worstStretch = std::max(worstStretch, maxStretchRatio(*net));
  }
  std::printf("max stretch: largest length/rest %.12f (limit 1.1), length/limit %.12f\n",
              worstStretch, worst);
  EXPECT_LE(worst, 1.0 + 1e-9);
  EXPECT_GT(worstStretch, 1.09);  // the constraint was active
  // Without the constraint the same load stretches a spring far beyond the limit.
  grid.maxStretch = 0;
  auto free = generateGrid(grid);
  ASSERT_TRUE(free);
  for (int s = 0; s < 300; ++s) step(*free, load, options);
  EXPECT_GT(maxStretchRatio(*free), 1.3);
}

// A net hanging at its stretch limits (the paper scene's net: 20 x 20, 8 kg, 300 N/m) must still
// answer a push: the projection used to stall over the long chains of springs at their limits and
// back the whole net off to where it was. Hangs it 1.5 s, then pushes its middle node up with 3 N
// for 0.3 s; `internal` springs in `substeps` sub-steps, or applied once per step from outside.
void expectTheHangingNetMovesUnderAPush(bool internal, int substeps) {
  auto net = generateGrid(paperSceneNet());
  ASSERT_TRUE(net) << net.error().message;
  StepOptions options;
  options.dt = 0.01;
  options.substeps = substeps;
  options.internalSprings = internal;
  options.gravity = {0, -9.81, 0};
  const std::size_t middle = 10 * 20 + 10;
  double worst = 0;
  int identical = 0, atLimit = 0;
  auto advance = [&](double push) {
    std::vector<double> forces(3 * net->nodeCount(), 0.0);
    if (!internal) addSpringForces(*net, forces);
    forces[3 * middle + 1] += push;
    const std::vector<double> before = net->positions;
    step(*net, forces, options);
    worst = std::max(worst, maxConstraintRatio(*net));
    if (net->positions == before) ++identical;
  };
  for (int s = 0; s < 150; ++s) {
    advance(0.0);
    if (s >= 100 && maxConstraintRatio(*net) > 1.0 - 1e-6) ++atLimit;
  }
  EXPECT_EQ(atLimit, 50);  // it hangs at its limits
  const double hanging = net->positions[3 * middle + 1];
  identical = 0;
  for (int s = 0; s < 30; ++s) advance(3.0);
  const double rise = net->positions[3 * middle + 1] - hanging;
  std::printf(
      "hanging net (%s springs, %d sub-steps): middle node rose %.4f m under 3 N in 0.3 s, "
      "length/limit %.12f\n",
      internal ? "internal" : "external", substeps, rise, worst);
  EXPECT_GT(rise, 0.02);
  EXPECT_EQ(identical, 0);  // never frozen bit for bit under the push
  EXPECT_LE(worst, 1.0 + 1e-9);
}

// As the paper's spring interactor applies them: once per 10 ms step.
TEST(MassSpringPhysics, NetHangingAtItsLimitsStillMovesUnderAPush) {
  expectTheHangingNetMovesUnderAPush(false, 1);
}

// As every paper-scene copy now integrates them: in the animator, 3 sub-steps.
TEST(MassSpringPhysics, NetHangingAtItsLimitsStillMovesUnderAPushWithItsSpringsInThreeSubSteps) {
  expectTheHangingNetMovesUnderAPush(true, 3);
}

// StepOptions::warmStart is state the caller can touch: a wrong count is replaced by zeros, and
// values that are not finite and positive are dropped; large ones cost the step, not the limits.
TEST(MassSpringPhysics, GarbageWarmStartNeitherBreaksTheLimitsNorPoisonsTheNet) {
  GridParams grid;
  grid.n = grid.m = 8;
  grid.mass = 1.0;
  grid.stiffness = 100.0;
  auto net = generateGrid(grid);
  ASSERT_TRUE(net);
  StepOptions options;
  options.gravity = {0, -9.81, 0};
  for (int s = 0; s < 100; ++s) step(*net, {}, options);  // hanging at its limits
  ASSERT_EQ(options.warmStart.size(), net->springs.size());
  const double values[] = {std::nan(""), INFINITY, -INFINITY, -1.0, 1e6};
  for (std::size_t i = 0; i < options.warmStart.size(); ++i) options.warmStart[i] = values[i % 5];
  for (int s = 0; s < 20; ++s) {
    step(*net, {}, options);
    for (double x : net->positions) ASSERT_TRUE(std::isfinite(x)) << s;
    ASSERT_LE(maxConstraintRatio(*net), 1.0 + 1e-9) << s;
  }
  options.warmStart.assign(3, 1.0);  // not one per spring: ignored
  step(*net, {}, options);
  EXPECT_EQ(options.warmStart.size(), net->springs.size());
  EXPECT_LE(maxConstraintRatio(*net), 1.0 + 1e-9);
}

TEST(MassSpringPhysics, EnergyDoesNotGrowForAnUndampedNet) {
  GridParams grid;
  grid.n = grid.m = 10;
  grid.spacing = 0.1;
  grid.mass = 1.0;
  grid.stiffness = 300.0;
  grid.damping = 0.0;
  grid.maxStretch = 0.0;  // the projection removes energy; test the integrator alone
  auto net = generateGrid(grid);
  ASSERT_TRUE(net);
  StepOptions options;
  options.dt = 0.01;
  options.substeps = 40;
  options.gravity = {0, -9.81, 0};
  auto energy = [&] {
    return kineticEnergy(*net) + elasticEnergy(*net) + gravityEnergy(*net, options.gravity);
  };
  const double e0 = energy();
  // Symplectic Euler's energy oscillates (O(h)) without a trend: compare the mean energy of the
  // first and last 5 s, and bound the largest excess over the start.
  double scale = 0, highest = e0, first = 0, last = 0;
  const int steps = 3000, window = 500;  // 30 s, 5 s
  for (int s = 0; s < steps; ++s) {
    step(*net, {}, options);
    const double e = energy();
    highest = std::max(highest, e);
    scale = std::max(scale, kineticEnergy(*net));
    if (s < window) first += e / window;
    if (s >= steps - window) last += e / window;
  }
  const double drift = (last - first) / scale;
  const double peak = (highest - e0) / scale;
  std::printf(
      "undamped net: 30 s, mean energy last 5 s - first 5 s = %.3e, highest excess %.3e "
      "(of the largest kinetic energy %.4f J)\n",
      drift, peak, scale);
  ASSERT_GT(scale, 0.1);  // it really moved
  EXPECT_LT(peak, 0.01);
  EXPECT_LT(drift, 0.002);
}

TEST(MassSpringPhysics, DampedNetComesToRestAndPinnedNodesNeverMove) {
  GridParams grid;
  grid.n = grid.m = 8;
  grid.origin = {1, 2, 3};
  auto net = generateGrid(grid);
  ASSERT_TRUE(net);
  const Net start = *net;
  StepOptions options;
  options.gravity = {0, -9.81, 0};
  double peak = 0;
  for (int s = 0; s < 1500; ++s) {
    step(*net, {}, options);
    peak = std::max(peak, kineticEnergy(*net));
  }
  EXPECT_LT(kineticEnergy(*net), 0.05 * peak);  // spring damping takes the motion out
  for (std::size_t i = 0; i < net->nodeCount(); ++i) {
    if (net->pinned[i]) {
      EXPECT_EQ(net->position(i), start.position(i)) << i;
    } else {
      EXPECT_LT(net->positions[3 * i + 1], 2.0) << i;  // it sags
    }
  }
}

TEST(MassSpringPhysics, ExternalForcesAreHeldOverTheSubSteps) {
  // One free node, no springs: a force F held for dt gives v = F dt / m whatever the sub-steps,
  // and x = F/m * h^2 * s(s+1)/2 for s sub-steps of h (symplectic Euler).
  Net net;
  net.positions = {0, 0, 0};
  net.velocities = {0, 0, 0};
  net.masses = {2.0};
  net.pinned = {0};
  StepOptions options;
  options.dt = 0.1;
  options.substeps = 4;
  const std::vector<double> force = {4.0, 0, 0};
  step(net, force, options);
  EXPECT_NEAR(net.velocities[0], 0.2, 1e-15);
  const double h = 0.025;
  EXPECT_NEAR(net.positions[0], 2.0 * h * h * 10, 1e-15);
}

}  // namespace
}  // namespace vrflow::massspring
