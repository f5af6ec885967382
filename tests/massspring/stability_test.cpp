// The stability of explicit spring integration: the net's fastest mode against analytic answers,
// and the paper scene's net (20 x 20, 8 kg, 300 N/m, damping 0.2) integrated with its springs in
// the animator's sub-steps against springs applied once per 10 ms step.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "paper_net.hpp"
#include "vrflow/massspring/solver.hpp"

namespace vrflow::massspring {
namespace {

// `count` free nodes of mass m in a row along x, between two pinned ends, springs of stiffness
// k, each `stretch` times its rest length 0.1.
Net chain(int count, double m, double k, double stretch) {
  Net net;
  for (int i = 0; i < count + 2; ++i) {
    net.positions.insert(net.positions.end(), {0.1 * stretch * i, 0.0, 0.0});
    net.velocities.insert(net.velocities.end(), {0.0, 0.0, 0.0});
    net.masses.push_back(m);
    net.pinned.push_back(i == 0 || i == count + 1 ? 1 : 0);
  }
  for (int i = 0; i <= count; ++i)
    net.springs.push_back(
        {static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i + 1), 0.1, k, 0.0, 0.0});
  return net;
}

TEST(SpringStability, FastestFrequencyIsTheAnalyticOneOfChains) {
  // A chain at rest moves only along itself: omega_max = sqrt(4 k / m) sin(N pi / (2 (N + 1))).
  const double k = 100, m = 0.1;
  const Net rest = chain(10, m, k, 1.0);
  const double expected = std::sqrt(4 * k / m) * std::sin(10 * std::numbers::pi / 22);
  EXPECT_NEAR(fastestSpringFrequency(rest), expected, 1e-6 * expected);
  // One node between two pins, springs stretched to 1.25 times their rest length: sqrt(2 k / m)
  // along the chain, sqrt(2 k (1 - 1 / 1.25) / m) across it; the fastest is along.
  const Net one = chain(1, m, k, 1.25);
  EXPECT_NEAR(fastestSpringFrequency(one), std::sqrt(2 * k / m), 1e-9);
  // Nothing that can move, or no stiffness: no mode.
  Net pinned = rest;
  pinned.pinned.assign(pinned.nodeCount(), 1);
  EXPECT_EQ(fastestSpringFrequency(pinned), 0.0);
  Net slack = rest;
  for (auto& s : slack.springs) s.stiffness = 0;
  EXPECT_EQ(fastestSpringFrequency(slack), 0.0);
  // Bad input gives a number, never a crash: no iteration, no node, a position that is not finite.
  EXPECT_EQ(fastestSpringFrequency(rest, 0), 0.0);
  EXPECT_EQ(fastestSpringFrequency(Net{}), 0.0);
  Net broken = rest;
  broken.positions[3 * 5 + 1] = std::nan("");
  EXPECT_TRUE(std::isfinite(fastestSpringFrequency(broken)));
  // Never above the true value, whatever the iteration count (a Rayleigh quotient).
  const Net longer = chain(40, m, k, 1.0);
  const double top = std::sqrt(4 * k / m) * std::sin(40 * std::numbers::pi / 82);
  for (int iterations : {1, 5, 50, 300}) EXPECT_LE(fastestSpringFrequency(longer, iterations), top);
  EXPECT_GT(fastestSpringFrequency(longer), 0.99 * top);
}

// The paper scene's net without its stretch limit (nothing hides an instability): with the
// springs applied once per 10 ms step (what the `spring` interactor does) omega dt = 3.0 is past
// the explicit limit of 2 and it blows up; in the animator's 3 sub-steps (omega h = 1.0) it stays
// bounded for 1,000 steps (10 s).
TEST(SpringStability, ThePaperScenesNetStaysBoundedInSubStepsAndBlowsUpWithSpringsOnceAStep) {
  auto grid = paperSceneNet();
  grid.maxStretch = 0;
  const auto start = generateGrid(grid);
  ASSERT_TRUE(start) << start.error().message;
  const double omega = fastestSpringFrequency(*start);
  std::printf("paper net: omega %.2f rad/s, omega dt %.3f at 10 ms, %.3f at 10/3 ms\n", omega,
              omega * 0.01, omega * 0.01 / 3);
  EXPECT_GT(omega * 0.01, 2.0);
  EXPECT_LT(omega * 0.01 / 3, 1.05);

  // The largest node speed over 1,000 steps (infinity once a value is not finite).
  auto fastestOver = [&](bool internal, int substeps) -> double {
    Net net = *start;
    StepOptions options;
    options.dt = 0.01;
    options.substeps = substeps;
    options.internalSprings = internal;
    options.gravity = {0, -9.81, 0};
    std::vector<double> forces(3 * net.nodeCount());
    double fastest = 0;
    for (int s = 0; s < 1000; ++s) {
      std::fill(forces.begin(), forces.end(), 0.0);
      if (!internal) addSpringForces(net, forces);  // the spring interactor's forces
      step(net, forces, options);
      for (std::size_t i = 0; i < net.nodeCount(); ++i) {
        const auto v = net.velocity(i);
        const double speed = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (!std::isfinite(speed) || !std::isfinite(net.position(i)[1])) return HUGE_VAL;
        fastest = std::max(fastest, speed);
      }
    }
    return fastest;
  };
  const double inSubSteps = fastestOver(true, 3);
  const double onceAStep = fastestOver(false, 1);
  std::printf("fastest node over 10 s: %.3f m/s in 3 sub-steps, %g once a step\n", inSubSteps,
              onceAStep);
  EXPECT_LT(inSubSteps, 6.0);  // a free fall of the sagging middle: about 5 m/s
  EXPECT_GT(onceAStep, 1e3);
}

}  // namespace
}  // namespace vrflow::massspring
