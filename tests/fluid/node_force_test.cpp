// The liquid's force on a net's node (issue 26, node_coupling.hpp): buoyancy of the sphere's
// submerged cap, implicit drag against the liquid's velocity, nothing for a dry node, and a
// force for nodes smaller than a cell. Compared with Archimedes and the drag of a sphere.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "tank.hpp"
#include "vrflow/fluid/solver.hpp"

namespace vrflow::fluid {
namespace {

using testing::cornerLevel;
using testing::makeTank;
using testing::smallTank;

constexpr double kRho = 1000.0;
constexpr double kG = 9.81;

double sphereVolume(double r) {
  return 4.0 / 3.0 * std::numbers::pi * r * r * r;
}

/// Depth d of a sphere's lowest point below the level at which the cap below holds `fraction`
/// of its volume: d^2 (3 r - d) / (4 r^3) = fraction, by bisection.
double capDepth(double r, double fraction) {
  double lo = 0.0, hi = 2.0 * r;
  for (int i = 0; i < 100; ++i) {
    const double d = 0.5 * (lo + hi);
    (d * d * (3 * r - d) / (4 * r * r * r) < fraction ? lo : hi) = d;
  }
  return 0.5 * (lo + hi);
}

/// A node integrated here from the liquid's force as the massspring animator does (semi-implicit
/// Euler, its own gravity), with an extra constant force and the tank's floor.
struct FreeNode {
  PointMass node;
  double push = 0.0;  ///< downward force added by the test (N)

  FreeNode(double mass, double radius, msg::Vec3 at) {
    node.id = 3;
    node.index = 4;
    node.mass = mass;
    node.radius = radius;
    node.position = at;
  }

  BodyForce step(FluidSolver& fluid, double dt) {
    auto forces = fluid.step(dt, {}, {node});
    EXPECT_TRUE(forces.ok()) << (forces.ok() ? "" : forces.error().message);
    const BodyForce f = forces->front();
    for (std::size_t a = 0; a < 3; ++a) {
      const double g = a == 1 ? -kG - push / node.mass : 0.0;
      node.velocity[a] += (f.force[a] / node.mass + g) * dt;
      node.position[a] += node.velocity[a] * dt;
    }
    if (node.position[1] < node.radius) {
      node.position[1] = node.radius;
      node.velocity[1] = std::max(0.0, node.velocity[1]);
    }
    return f;
  }
};

/// Floats a node from 3 cm into still water for 3 s; returns the mean depth of its lowest point
/// below the tank's level over the last second, and the fastest it moved.
struct Floating {
  double depth = 0.0;
  double fastest = 0.0;
  double lowest = 1e9;
};

Floating floatNode(double mass, double radius, double push) {
  auto tank = makeTank(smallTank(16, 20, 16), 0.5);
  const double level = cornerLevel(*tank);
  FreeNode n(mass, radius, {0.4, level + radius - 0.03, 0.4});
  n.push = push;
  Floating out;
  int samples = 0;
  for (int step = 0; step < 300; ++step) {
    n.step(*tank, 0.01);
    const double speed = std::abs(n.node.velocity[1]);
    out.fastest = std::max(out.fastest, speed);
    out.lowest = std::min(out.lowest, n.node.position[1]);
    if (step >= 200) {
      out.depth += cornerLevel(*tank) - (n.node.position[1] - radius);
      ++samples;
    }
  }
  out.depth /= samples;
  return out;
}

// A 20 g node of 5 cm (26 times lighter than the water it would displace) floats with
// rho_node / rho_water of its volume submerged: its lowest point 1.15 cm under the surface.
TEST(NodeForce, LightNodeFloatsAtArchimedesDepth) {
  const double m = 0.02, r = 0.05;
  const auto f = floatNode(m, r, 0.0);
  const double expected = capDepth(r, m / (kRho * sphereVolume(r)));
  std::printf("20 g node: depth %.4f m (Archimedes %.4f), fastest %.3f m/s\n", f.depth, expected,
              f.fastest);
  // The level comes from particle counts (8 a cell), and the node's reaction presses a dimple
  // into the surface under it (its sphere does not displace the particles): within 0.3 cells.
  EXPECT_NEAR(f.depth, expected, 0.015);
  EXPECT_LT(f.fastest, 1.0);
}

// Pushed down by 2 N (less than its 5.1 N full buoyancy), it floats where buoyancy balances
// its weight and the push: 43 % of its volume under water (before: it fell to the bottom).
TEST(NodeForce, PushedNodeFloatsWhereBuoyancyBalancesWeightAndPush) {
  const double m = 0.02, r = 0.05, push = 2.0;
  const auto f = floatNode(m, r, push);
  const double fraction = (m * kG + push) / (kRho * kG * sphereVolume(r));
  const double expected = capDepth(r, fraction);
  std::printf(
      "20 g node pushed with 2 N: depth %.4f m (Archimedes %.4f, %.0f %% of its volume), "
      "lowest y %.3f, fastest %.3f m/s\n",
      f.depth, expected, 100 * fraction, f.lowest, f.fastest);
  EXPECT_NEAR(f.depth, expected, 0.015);  // as above
  EXPECT_GT(f.lowest, 0.4);               // never near the bottom
}

// Pushed with more than its buoyancy can carry, it sinks at the terminal speed where drag takes
// the rest: 0.5 rho C_d pi r^2 v^2 = m g + push - rho g V.
TEST(NodeForce, OverloadedNodeSinksAtTheDragsTerminalSpeed) {
  const double m = 0.02, r = 0.05, push = 6.0;
  auto tank = makeTank(smallTank(16, 24, 16), 0.9);
  FreeNode n(m, r, {0.4, 0.75, 0.4});
  n.push = push;
  double sum = 0.0;
  int samples = 0;
  for (int step = 0; step < 40 && n.node.position[1] > 0.2; ++step) {
    n.step(*tank, 0.01);
    if (step >= 10) {
      sum += -n.node.velocity[1];
      ++samples;
    }
  }
  ASSERT_GT(samples, 5);
  const double terminal = std::sqrt((m * kG + push - kRho * kG * sphereVolume(r)) /
                                    (0.5 * kRho * 0.47 * std::numbers::pi * r * r));
  std::printf("node pushed with 6 N: sinks at %.3f m/s (terminal speed in still water %.3f)\n",
              sum / samples, terminal);
  // The liquid it pushes moves down with it (the reaction), and the drag is taken against that
  // liquid: the node sinks faster than through still water (1.64 times measured), never freely
  // (pushed at 31 g it would reach 9 m/s in these 0.3 s).
  EXPECT_GT(sum / samples, 0.8 * terminal);
  EXPECT_LT(sum / samples, 2.0 * terminal);
}

// A node whose sphere ends 5 cm above still water has no liquid in it: exactly zero force. On
// the paper scene's grid (cells of 6.25 cm, the pool 0.85 m deep) the mass-aware force lifted
// such a node with 0.18 N of its 0.196 N weight.
TEST(NodeForce, DryNodeAboveTheSurfaceGetsExactlyZero) {
  for (const double cell : {0.05, 0.0625}) {
    auto settings = smallTank(16, 20, 16);
    settings.cellSize = cell;
    auto tank = makeTank(settings, 0.85);
    PointMass node;
    node.id = 1;
    node.mass = 0.02;
    node.radius = 0.05;
    node.position = {8.5 * cell, cornerLevel(*tank) + 0.05 + node.radius, 8.5 * cell};
    for (int step = 0; step < 20; ++step) {
      auto forces = tank->step(0.01, {}, {node});
      ASSERT_TRUE(forces.ok());
      EXPECT_EQ(forces->front().force, (msg::Vec3{0, 0, 0}))
          << "cells " << cell << " step " << step;
      EXPECT_GT(forces->front().cells, 0);  // in the grid: a record of zero
    }
  }
}

// A node moved sideways through still water: the force opposes its velocity, grows with it as
// the drag of a sphere (0.5 rho C_d pi r^2 v^2 for a heavy node), and for a light node never
// reverses its velocity relative to the liquid in one step.
TEST(NodeForce, DragOpposesTheMotionGrowsWithSpeedAndNeverOvershoots) {
  const double r = 0.05;
  double previous = 0.0;
  for (double v : {0.25, 0.5, 1.0, 2.0}) {
    auto tank = makeTank(smallTank(16, 20, 16), 0.6);
    PointMass node;
    node.mass = 10.0;  // heavy: the implicit factor is 1 + k dt / m ~ 1
    node.radius = r;
    node.position = {0.4, 0.3, 0.4};
    node.velocity = {v, 0, 0};
    auto forces = tank->step(0.01, {}, {node});
    ASSERT_TRUE(forces.ok());
    const auto& f = forces->front().force;
    const double analytic = 0.5 * kRho * 0.47 * std::numbers::pi * r * r * v * v;
    std::printf("drag at %.2f m/s: %.3f N (sphere %.3f N)\n", v, -f[0], analytic);
    EXPECT_LT(f[0], 0.0);
    EXPECT_GT(-f[0], previous);
    EXPECT_NEAR(-f[0], analytic, 0.05 * analytic);
    previous = -f[0];
  }
  for (double v : {1.0, 10.0, 100.0}) {
    auto tank = makeTank(smallTank(16, 20, 16), 0.6);
    PointMass node;
    node.mass = 0.02;
    node.radius = r;
    node.position = {0.4, 0.3, 0.4};
    node.velocity = {v, 0, 0};
    auto forces = tank->step(0.01, {}, {node});
    ASSERT_TRUE(forces.ok());
    const double after = v + forces->front().force[0] * 0.01 / node.mass;
    std::printf("20 g node at %.0f m/s: %.3f m/s after one step\n", v, after);
    EXPECT_LT(after, v);
    EXPECT_GT(after, 0.0);  // the liquid is at rest: never pushed backwards
  }
}

// A node far smaller than a cell (radius 0.3 h < h / sqrt 6, which reached no face centre and got
// nothing) held under water at rest gets its buoyancy rho g V.
TEST(NodeForce, NodeSmallerThanACellGetsItsBuoyancy) {
  auto tank = makeTank(smallTank(12, 16, 12), 0.6);
  PointMass node;
  node.mass = 0.001;
  node.radius = 0.3 * 0.05;
  node.position = {0.31, 0.27, 0.29};
  for (int step = 0; step < 3; ++step) ASSERT_TRUE(tank->step(0.01, {}, {node}).ok());
  auto forces = tank->step(0.01, {}, {node});
  ASSERT_TRUE(forces.ok());
  const double buoyancy = kRho * kG * sphereVolume(node.radius);
  std::printf("node of 0.3 cells: force y %.5f N (buoyancy %.5f N)\n", forces->front().force[1],
              buoyancy);
  EXPECT_GT(forces->front().cells, 0);
  EXPECT_NEAR(forces->front().force[1], buoyancy, 0.02 * buoyancy);
  EXPECT_NEAR(forces->front().force[0], 0.0, 0.05 * buoyancy);
}

// Bad nodes stop the step with the node named, before anything moves.
TEST(NodeForce, BadNodeIsRejectedWithItsName) {
  auto tank = makeTank(smallTank(8, 8, 8), 0.2);
  PointMass node;
  node.id = 12;
  node.index = 7;
  node.radius = 0.05;
  node.position = {0.2, 0.1, 0.2};
  node.velocity = {std::nan(""), 0, 0};
  auto forces = tank->step(0.01, {}, {node});
  ASSERT_FALSE(forces.ok());
  EXPECT_NE(forces.error().message.find("body 12"), std::string::npos) << forces.error().message;
  node.velocity = {};
  node.mass = -1;
  forces = tank->step(0.01, {}, {node});
  ASSERT_FALSE(forces.ok());
  EXPECT_NE(forces.error().message.find("mass"), std::string::npos) << forces.error().message;
}

}  // namespace
}  // namespace vrflow::fluid
