#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "tank.hpp"
#include "vrflow/fluid/solver.hpp"

namespace vrflow::fluid {
namespace {

using testing::cornerLevel;
using testing::makeTank;
using testing::smallTank;

// A box integrated here from the forces the fluid returns (semi-implicit Euler, translation
// only: the tests are about buoyancy and drag, and a cube of density 0.5 would roll), with the
// tank's floor as a contact.
struct TestBox {
  RigidBody body;
  double half = 0.0;

  TestBox(double halfEdge, double relativeDensity, msg::Vec3 position) : half(halfEdge) {
    body.id = 7;
    body.shape = msg::Shape::box({halfEdge, halfEdge, halfEdge});
    body.position = position;
    body.mass = relativeDensity * 1000.0 * 8 * halfEdge * halfEdge * halfEdge;
  }

  void integrate(const BodyForce& f, double dt) {
    for (int a = 0; a < 3; ++a) {
      const double g = a == 1 ? -9.81 : 0.0;
      body.linearVelocity[a] += (f.force[a] / body.mass + g) * dt;
      body.position[a] += body.linearVelocity[a] * dt;
    }
    if (body.position[1] - half < 0.0) {  // the floor
      body.position[1] = half;
      body.linearVelocity[1] = std::max(0.0, body.linearVelocity[1]);
    }
  }

  double bottom() const { return body.position[1] - half; }
};

BodyForce stepWith(FluidSolver& solver, TestBox& box, double dt) {
  auto forces = solver.step(dt, {box.body});
  EXPECT_TRUE(forces.ok()) << (forces.ok() ? "" : forces.error().message);
  EXPECT_EQ(forces->size(), 1u);
  const BodyForce f = forces->front();
  EXPECT_EQ(f.id, box.body.id);
  box.integrate(f, dt);
  return f;
}

TEST(RigidFluidCoupling, BoxOfHalfTheWatersDensityFloatsHalfSubmerged) {
  auto tank = makeTank(smallTank(16, 20, 16), 0.5);
  TestBox box(0.15, 0.5, {0.4, 0.5, 0.4});  // 6 cells wide, centred on the surface
  const double dt = 0.01;
  double sumSubmerged = 0.0, sumSpeed = 0.0;
  int samples = 0;
  for (int step = 0; step < 300; ++step) {
    stepWith(*tank, box, dt);
    if (step >= 200) {
      sumSubmerged += (cornerLevel(*tank) - box.bottom()) / (2 * box.half);
      sumSpeed += std::abs(box.body.linearVelocity[1]);
      ++samples;
    }
  }
  const double submerged = sumSubmerged / samples;
  const double speed = sumSpeed / samples;
  std::printf(
      "density 0.5 box: submerged fraction %.3f, |v| %.3f m/s (means of steps 200-300), y %.3f\n",
      submerged, speed, box.body.position[1]);
  EXPECT_NEAR(submerged, 0.5, 0.15);
  // It bobs about 2 cm in the closed tank (up to 0.17 m/s): at rest on average, not at every step.
  EXPECT_LT(speed, 0.1);
  EXPECT_GT(box.bottom(), 0.1);  // still afloat, far from the floor
}

TEST(RigidFluidCoupling, BoxOfTwiceTheWatersDensitySinksToTheFloor) {
  auto tank = makeTank(smallTank(16, 20, 16), 0.5);
  TestBox box(0.1, 2.0, {0.4, 0.4, 0.4});
  const double dt = 0.01;
  double fastest = 0.0;
  int floorStep = -1;
  for (int step = 0; step < 200 && floorStep < 0; ++step) {
    const auto f = stepWith(*tank, box, dt);
    (void)f;
    fastest = std::max(fastest, -box.body.linearVelocity[1]);
    if (box.bottom() <= 1e-9) floorStep = step;
  }
  std::printf("density 2 box: reached the floor at step %d, fastest sinking %.3f m/s\n", floorStep,
              fastest);
  ASSERT_GE(floorStep, 0) << "the heavy box never reached the floor";
  // Free fall through 0.3 m takes 0.25 s; buoyancy (half the weight) and drag make it slower.
  EXPECT_GT(floorStep, 30);
}

TEST(RigidFluidCoupling, DroppedBoxSlowsDownAndRaisesTheWater) {
  auto tank = makeTank(smallTank(16, 24, 16), 0.4);
  for (int step = 0; step < 5; ++step) ASSERT_TRUE(tank->step(0.01, {}).ok());
  const double level0 = cornerLevel(*tank);
  TestBox box(0.125, 0.9, {0.4, 0.8, 0.4});
  const double dt = 0.01;
  double entrySpeed = 0.0;
  double slowest = 1e9;
  double waterSpeed = 0.0;
  // The level sloshes by about 2 cm after the box goes in: its mean over the last 50 steps.
  double level1 = 0.0;
  for (int step = 0; step < 150; ++step) {
    stepWith(*tank, box, dt);
    const double speed = -box.body.linearVelocity[1];
    if (box.bottom() > level0)
      entrySpeed = speed;
    else
      slowest = std::min(slowest, speed);
    waterSpeed = std::max(waterSpeed, tank->maxParticleSpeed());
    if (step >= 100) level1 += cornerLevel(*tank) / 50;
  }
  std::printf(
      "dropped box: entry %.3f m/s, slowest after entry %.3f m/s, level %.4f -> %.4f, "
      "water speed %.3f m/s\n",
      entrySpeed, slowest, level0, level1, waterSpeed);
  EXPECT_GT(entrySpeed, 1.0);
  EXPECT_LT(slowest, 0.5 * entrySpeed);
  // 0.9 of the box's 15.6 litres under water spread over the 0.64 m^2 tank: about 2 cm.
  EXPECT_GT(level1 - level0, 0.01);
  EXPECT_GT(waterSpeed, 0.2);
}

}  // namespace
}  // namespace vrflow::fluid

namespace vrflow::fluid {
namespace {

// A box spinning about z in still water: the liquid resists, so the torque opposes the spin;
// the same box at rest gets (almost) no torque, and its force is buoyancy (upward).
TEST(RigidFluidCoupling, SpinningBoxFeelsATorqueAgainstItsSpin) {
  auto tank = testing::makeTank(testing::smallTank(16, 16, 16), 0.6);
  RigidBody box;
  box.id = 3;
  box.shape = msg::Shape::box({0.1, 0.1, 0.1});
  box.position = {0.4, 0.3, 0.4};
  box.mass = 1000.0 * 0.008;  // neutrally buoyant
  // Held still while the particles it displaced settle around it.
  for (int step = 0; step < 100; ++step) ASSERT_TRUE(tank->step(0.01, {box}).ok());
  auto atRest = tank->step(0.01, {box});
  ASSERT_TRUE(atRest.ok());
  const auto& rest = atRest->front();
  box.angularVelocity = {0, 0, 4.0};
  auto spinning = tank->step(0.01, {box});
  ASSERT_TRUE(spinning.ok());
  const auto& spin = spinning->front();
  std::printf(
      "box at rest: force y %.2f N (weight %.2f N), torque z %.4f N m; spinning: torque "
      "z %.4f N m\n",
      rest.force[1], box.mass * 9.81, rest.torque[2], spin.torque[2]);
  EXPECT_NEAR(rest.force[1], box.mass * 9.81, 0.1 * box.mass * 9.81);  // buoyancy = weight
  EXPECT_LT(std::abs(rest.torque[2]), 0.05);  // particle noise; the spin gives ~2 N m
  EXPECT_LT(spin.torque[2], -0.1);            // against the spin
}

// A mass-spring node under water is pushed up (buoyancy), gets no torque.
TEST(RigidFluidCoupling, SubmergedNetNodeIsPushedUp) {
  auto tank = testing::makeTank(testing::smallTank(12, 12, 12), 0.45);
  PointMass node;
  node.id = 9;
  node.index = 17;
  node.position = {0.3, 0.2, 0.3};
  node.mass = 0.2;
  node.radius = 0.06;
  for (int step = 0; step < 3; ++step) ASSERT_TRUE(tank->step(0.01, {}, {node}).ok());
  auto forces = tank->step(0.01, {}, {node});
  ASSERT_TRUE(forces.ok());
  ASSERT_EQ(forces->size(), 1u);
  const auto& f = forces->front();
  const double displaced = 1000.0 * 4.0 / 3.0 * 3.14159265 * 0.06 * 0.06 * 0.06;
  const double buoyancy = 9.81 * displaced;
  // The node's own force (node_force_test.cpp): held still in still water, its buoyancy.
  std::printf("net node: force y %.3f N (buoyancy of the sphere %.3f N), %d faces\n", f.force[1],
              buoyancy, f.cells);
  EXPECT_EQ(f.index, 17u);
  EXPECT_GT(f.cells, 0);
  EXPECT_NEAR(f.force[1], buoyancy, 0.02 * buoyancy);
  EXPECT_EQ(f.torque, (msg::Vec3{0, 0, 0}));
}

}  // namespace
}  // namespace vrflow::fluid

namespace vrflow::fluid {
namespace {

// A kinematic body (mass ignored, as the rigid package's mass-0 bodies) is a moving wall: held
// still, the water it displaced only sloshes down (its 9 litres raised a 0.32 m^2 tank by 3 cm);
// driven at 0.5 m/s through the 0.4 m wide tank, it squeezes the water past it much faster.
TEST(RigidFluidCoupling, KinematicBoxDrivenThroughWaterStirsIt) {
  auto tank = testing::makeTank(testing::smallTank(16, 12, 8), 0.4);
  RigidBody paddle;
  paddle.id = 5;
  paddle.kinematic = true;
  paddle.mass = 0.0;
  paddle.shape = msg::Shape::box({0.05, 0.15, 0.15});
  paddle.position = {0.2, 0.2, 0.2};
  // Held still while the water it displaced settles.
  for (int step = 0; step < 150; ++step) ASSERT_TRUE(tank->step(0.01, {paddle}).ok());
  const double still = tank->maxParticleSpeed();
  paddle.linearVelocity = {0.5, 0, 0};
  for (int step = 0; step < 20; ++step) {
    ASSERT_TRUE(tank->step(0.01, {paddle}).ok());
    paddle.position[0] += 0.5 * 0.01;
  }
  const double stirred = tank->maxParticleSpeed();
  std::printf("kinematic paddle: water speed %.4f m/s held, %.3f m/s driven at 0.5 m/s\n", still,
              stirred);
  EXPECT_LT(still, 0.3);
  EXPECT_GT(stirred, 0.5);
  EXPECT_GT(stirred, 3 * still);
}

}  // namespace
}  // namespace vrflow::fluid

namespace vrflow::fluid {
namespace {

// Bodies out of the water. A body none of whose cells touches the liquid is in air, where the
// pressure is zero: the liquid must not reach it through another body's cells (the nodes of a
// net lying on the water, a floating box under it) nor push it for moving through air.

RigidBody cube(std::uint64_t id, double half, double density, msg::Vec3 position) {
  RigidBody b;
  b.id = id;
  b.shape = msg::Shape::box({half, half, half});
  b.position = position;
  b.mass = density * 8 * half * half * half;
  return b;
}

double length(const msg::Vec3& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

// The paper scene's objects (40 kg/m^3) resting on its net: a 5 x 5 patch of nodes (spheres of
// 5 cm, 10 cm apart) half in the water, a 20 cm box resting on them, 1 cell above the surface.
TEST(RigidFluidCoupling, BoxInAirOnNetNodesLyingOnTheWaterGetsNoForce) {
  auto tank = testing::makeTank(testing::smallTank(16, 20, 16), 0.5);
  std::vector<PointMass> nodes;
  for (int i = -2; i <= 2; ++i) {
    for (int k = -2; k <= 2; ++k) {
      PointMass n;
      n.id = 9;
      n.index = static_cast<std::uint32_t>(nodes.size());
      n.position = {0.4 + 0.1 * i, 0.5, 0.4 + 0.1 * k};
      n.mass = 0.25;
      n.radius = 0.05;
      nodes.push_back(n);
    }
  }
  const auto box = cube(1, 0.1, 40.0, {0.4, 0.65, 0.4});
  const double weight = box.mass * 9.81;
  double worst = 0.0, nodesUp = 0.0;
  for (int step = 0; step < 10; ++step) {
    auto forces = tank->step(0.01, {box}, nodes);
    ASSERT_TRUE(forces.ok());
    ASSERT_EQ(forces->size(), 1u + nodes.size());
    const auto& f = forces->front();
    EXPECT_GT(f.cells, 0);
    worst = std::max(worst, length(f.force));
    for (std::size_t n = 1; n < forces->size(); ++n) nodesUp += (*forces)[n].force[1] / 10;
  }
  std::printf("box on net nodes: largest |F| %.4f N (weight %.3f N); the nodes: %.2f N up\n", worst,
              weight, nodesUp);
  EXPECT_LT(worst, 0.01 * weight);
  EXPECT_GT(nodesUp, 1.0);  // the nodes themselves do touch the water
}

// A light box resting on a floating one: the light box gets nothing, and the floating box gets
// what it gets alone (the light box is air to the liquid).
TEST(RigidFluidCoupling, BoxInAirOnAFloatingBoxLeavesTheFloatingBoxAlone) {
  auto alone = testing::makeTank(testing::smallTank(16, 20, 16), 0.5);
  auto stacked = testing::makeTank(testing::smallTank(16, 20, 16), 0.5);
  const auto floating = cube(2, 0.1, 500.0, {0.4, 0.5, 0.4});
  const auto top = cube(1, 0.1, 40.0, {0.4, 0.7, 0.4});
  double worstTop = 0.0, worstDifference = 0.0;
  for (int step = 0; step < 10; ++step) {
    auto a = alone->step(0.01, {floating});
    auto s = stacked->step(0.01, {top, floating});
    ASSERT_TRUE(a.ok() && s.ok());
    worstTop = std::max(worstTop, length((*s)[0].force));
    const auto& f1 = (*s)[1].force;
    const auto& f0 = (*a)[0].force;
    worstDifference =
        std::max(worstDifference, length({f1[0] - f0[0], f1[1] - f0[1], f1[2] - f0[2]}));
  }
  std::printf(
      "box on a floating box: largest |F| %.4f N (weight %.3f N); the floating box's force "
      "differs from its force alone by %.4f N at most (weight %.2f N)\n",
      worstTop, top.mass * 9.81, worstDifference, floating.mass * 9.81);
  EXPECT_LT(worstTop, 0.01 * top.mass * 9.81);
  EXPECT_LT(worstDifference, 0.01 * floating.mass * 9.81);
}

// Air does not brake: a sphere falling and spinning 4 cells above the water, or falling 2 cm
// above it, gets no force and no torque.
TEST(RigidFluidCoupling, SphereMovingThroughAirGetsNoForce) {
  for (const double gap : {0.16, 0.02}) {
    auto tank = testing::makeTank(testing::smallTank(16, 20, 16), 0.5);
    RigidBody ball;
    ball.id = 4;
    ball.shape = msg::Shape::sphere(0.12);
    ball.position = {0.4, 0.5 + gap + 0.12, 0.4};
    ball.mass = 500.0 * 4.0 / 3.0 * 3.14159265 * 0.12 * 0.12 * 0.12;
    ball.linearVelocity = {0.3, -1.0, 0.0};
    ball.angularVelocity = {0.0, 0.0, 3.0};
    auto forces = tank->step(0.01, {ball});
    ASSERT_TRUE(forces.ok());
    const auto& f = forces->front();
    std::printf("sphere %.2f m above the water: |F| %.4f N (weight %.2f N), |torque| %.5f N m\n",
                gap, length(f.force), ball.mass * 9.81, length(f.torque));
    EXPECT_GT(f.cells, 0);
    EXPECT_LT(length(f.force), 0.01 * ball.mass * 9.81);
    EXPECT_LT(length(f.torque), 1e-3);
  }
}

}  // namespace
}  // namespace vrflow::fluid
