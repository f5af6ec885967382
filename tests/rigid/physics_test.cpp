// The rigid solvers against analytic answers and invariants, stepped in one process.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <set>
#include <vector>

#include "vrflow/rigid/scene.hpp"
#include "vrflow/rigid/world.hpp"

namespace vrflow::rigid {
namespace {

constexpr double kDt = 0.01;  // the demo's time step
const Vec3 kG{0, -9.81, 0};

ForceField gravityField() {
  return ForceField({FieldTerm{FieldTerm::Kind::Gravity, kG}});
}

Body ground(std::uint64_t id = 1) {
  return makeKinematic(id, msg::Shape::box({5, 0.5, 5}), {0, -0.5, 0});
}

double norm(const Vec3& v) {
  return asEigen(v).norm();
}

TEST(RigidPhysics, FreeFallMatchesSemiImplicitEulerAndTheAnalyticCurve) {
  RigidWorld world(gravityField(), {});
  Body ball = makeBody(7, msg::Shape::sphere(0.1), 2.0, {0, 10, 0});
  ball.linearVelocity = {1, 2, 0};
  ASSERT_TRUE(world.add({ball}));
  const int n = 100;
  for (int i = 0; i < n; ++i) world.step(kDt);
  const Body& b = *world.state().find(7);
  const double t = n * kDt;
  // Semi-implicit Euler: y_n = y0 + v0 t - g dt^2 n(n+1)/2, exact up to round-off.
  EXPECT_NEAR(b.position[1], 10 + 2 * t - 9.81 * kDt * kDt * n * (n + 1) / 2, 1e-9);
  EXPECT_NEAR(b.position[0], 1 * t, 1e-12);
  EXPECT_NEAR(b.linearVelocity[1], 2 - 9.81 * t, 1e-9);
  // The continuous answer differs by g dt t / 2.
  EXPECT_NEAR(b.position[1], 10 + 2 * t - 0.5 * 9.81 * t * t, 0.5 * 9.81 * kDt * t + 1e-9);
  EXPECT_DOUBLE_EQ(world.state().time(), t);
}

// Drops a sphere from `height` (its bottom), returns the first rebound's peak height.
double reboundHeight(double restitution, double height, double dt) {
  ContactParams params;
  params.restitution = restitution;
  params.restitutionThreshold = 0.1;
  RigidWorld world(gravityField(), params);
  const double r = 0.1;
  EXPECT_TRUE(world.add({ground(), makeBody(2, msg::Shape::sphere(r), 1.0, {0, height + r, 0})}));
  bool rising = false;
  double peak = 0;
  for (int i = 0; i < static_cast<int>(4.0 / dt); ++i) {
    world.step(dt);
    const Body& b = *world.state().find(2);
    if (b.linearVelocity[1] > 0) rising = true;
    if (rising) {
      peak = std::max(peak, b.position[1] - r);
      if (b.linearVelocity[1] < 0) break;
    }
  }
  EXPECT_TRUE(rising) << "the sphere never bounced";
  return peak;
}

TEST(RigidPhysics, BouncingSphereReboundsToRestitutionSquaredWhateverTheStep) {
  // The impact happens within a step, up to |v| dt above the ground; the bounce gives back e^2
  // of the energy at the touch (not -e v from where the step left the sphere, which rose 15 %
  // too high at dt = 0.01), so the rebound peak is e^2 of the drop at the scene's step too.
  for (double dt : {0.02, 0.01, 0.001}) {
    for (double height : {0.5, 1.0, 2.0}) {
      for (double e : {0.3, 0.5, 0.8}) {
        const double ratio = reboundHeight(e, height, dt) / height;
        std::printf("[bounce] e = %.1f, dt = %.3f, drop %.1f m: rebound ratio %.4f (e^2 = %.4f)\n",
                    e, dt, height, ratio, e * e);
        // 1 %, plus the peak's sampling: the highest step is within g dt^2 / 8 of the apex.
        EXPECT_NEAR(ratio, e * e, 0.01 * e * e + 9.81 * dt * dt / 8 / height)
            << "e = " << e << ", dt = " << dt;
      }
    }
  }
}

TEST(RigidPhysics, EachPairBouncesAndSlidesWithItsOwnMaterials) {
  // Restitution: the larger of the pair's. Two spheres dropped 1 m side by side onto a ground with
  // no material of its own (the solver's 0.3): the rubber one (0.8) rebounds to 0.64 m, the putty
  // one (0.1) to 0.3^2 = 0.09 m.
  {
    ContactParams params;
    params.restitution = 0.3;
    params.restitutionThreshold = 0.1;
    RigidWorld world(gravityField(), params);
    Body rubber = makeBody(2, msg::Shape::sphere(0.1), 1.0, {-1, 1.1, 0});
    rubber.restitution = 0.8;
    Body putty = makeBody(3, msg::Shape::sphere(0.1), 1.0, {1, 1.1, 0});
    putty.restitution = 0.1;
    ASSERT_TRUE(world.add({ground(), rubber, putty}));
    std::array<double, 2> peak{}, rising{};
    for (int i = 0; i < 400; ++i) {
      world.step(kDt);
      for (int k = 0; k < 2; ++k) {
        const Body& b = *world.state().find(static_cast<std::uint64_t>(2 + k));
        if (b.linearVelocity[1] > 0 && peak[k] == 0) rising[k] = 1;
        if (rising[k] == 1) {
          peak[k] = std::max(peak[k], b.position[1] - 0.1);
          if (b.linearVelocity[1] < 0) rising[k] = 2;
        }
      }
    }
    std::printf("[materials] rebound %.4f (0.8 on 0.3) and %.4f (0.1 on 0.3)\n", peak[0], peak[1]);
    EXPECT_NEAR(peak[0], 0.64, 0.01);
    EXPECT_NEAR(peak[1], 0.09, 0.005);
  }
  // Friction: the geometric mean. Boxes launched at 2 m/s along a ground with the solver's 0.6
  // stop after v^2 / (2 mu g): mu = sqrt(0.1 * 0.6) slides 0.83 m, sqrt(0.9 * 0.6) 0.28 m, less
  // v dt / 2 with semi-implicit Euler (each step moves with the velocity after its friction).
  {
    ContactParams params;
    params.friction = 0.6;
    RigidWorld world(gravityField(), params);
    world.state().setSleep({.enabled = false});
    const double h = 0.1;
    Body ice = makeBody(2, msg::Shape::box({h, h, h}), 1.0, {-2, h, -1});
    ice.friction = 0.1;
    Body rubber = makeBody(3, msg::Shape::box({h, h, h}), 1.0, {-2, h, 1});
    rubber.friction = 0.9;
    ice.linearVelocity = rubber.linearVelocity = {2, 0, 0};
    ASSERT_TRUE(world.add({ground(), ice, rubber}));
    for (int i = 0; i < 200; ++i) world.step(kDt);
    const double slid[2] = {world.state().find(2)->position[0] + 2,
                            world.state().find(3)->position[0] + 2};
    for (int k = 0; k < 2; ++k) {
      const double mu = std::sqrt((k == 0 ? 0.1 : 0.9) * 0.6);
      const double expected = 4.0 / (2 * mu * 9.81) - 2.0 * kDt / 2;
      std::printf("[materials] slid %.4f m, v^2/(2 mu g) - v dt/2 = %.4f m\n", slid[k], expected);
      EXPECT_NEAR(slid[k], expected, 0.01 * expected);
    }
  }
}

TEST(RigidPhysics, TwoBodyCollisionConservesMomentum) {
  ContactParams params;
  params.gravity = {0, 0, 0};
  params.restitution = 0.9;
  params.restitutionThreshold = 0.01;
  RigidWorld world(ForceField{}, params);
  Body a = makeBody(1, msg::Shape::sphere(0.2), 1.0, {-1, 0, 0});
  Body b = makeBody(2, msg::Shape::box({0.2, 0.15, 0.25}), 3.0, {1, 0.05, 0.02},
                    {0.0, 0.0, std::sin(0.2), std::cos(0.2)});
  a.linearVelocity = {2, 0.1, 0};
  b.linearVelocity = {-1, 0, 0.05};
  b.angularVelocity = {0, 0, 0.3};
  ASSERT_TRUE(world.add({a, b}));
  auto momentum = [&] {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (const Body& x : world.state().bodies()) p += asEigen(x.linearVelocity) * x.mass;
    return p;
  };
  auto angular = [&] {  // about the origin: r x m v + I_w w
    Eigen::Vector3d l = Eigen::Vector3d::Zero();
    for (const Body& x : world.state().bodies())
      l += asEigen(x.position).cross(asEigen(x.linearVelocity) * x.mass) + angularMomentum(x);
    return l;
  };
  const Eigen::Vector3d p0 = momentum(), l0 = angular();
  const double va0 = world.state().find(1)->linearVelocity[0];
  for (int i = 0; i < 150; ++i) world.step(kDt);
  const Eigen::Vector3d p1 = momentum(), l1 = angular();
  EXPECT_LT(world.state().find(1)->linearVelocity[0], va0 - 1.0) << "no collision happened";
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(p1[k], p0[k], 1e-9 * (1 + p0.norm()));
    EXPECT_NEAR(l1[k], l0[k], 1e-6 * (1 + l0.norm()));
  }
  // Separating after the impact.
  EXPECT_GT(world.state().find(2)->linearVelocity[0], world.state().find(1)->linearVelocity[0]);
}

TEST(RigidPhysics, StackOfFiveBoxesStandsForTenSeconds) {
  auto bodies = generateScene("stack:5");
  ASSERT_TRUE(bodies);
  RigidWorld world(gravityField(), {});
  world.state().setSleep({.enabled = false});  // the solver alone holds the stack
  ASSERT_TRUE(world.add(*bodies));
  const auto start = world.state().bodies();
  for (int i = 0; i < 1000; ++i) world.step(kDt);  // 10 s
  double drift = 0, speed = 0, tilt = 0;
  for (std::size_t i = 1; i < start.size(); ++i) {
    const Body& b = world.state().bodies()[i];
    drift = std::max(drift, (asEigen(b.position) - asEigen(start[i].position)).norm());
    speed = std::max(speed, norm(b.linearVelocity));
    tilt = std::max(tilt, std::abs(1 - std::abs(b.orientation[3])));
  }
  std::printf("[stack] max drift %.3g m, max speed %.3g m/s, max tilt %.3g\n", drift, speed, tilt);
  EXPECT_LT(drift, 0.005);  // 5 mm: the boxes sink by at most the slop each and stay in column
  EXPECT_LT(speed, 1e-3);
  EXPECT_LT(tilt, 1e-3);
  EXPECT_GT(world.state().bodies().back().position[1], 2.25 - 0.03);
}

// A structure of boxes left alone for 10 s with sleeping off (the solver alone holds it).
struct StandResult {
  double drift = 0, speed = 0, tilt = 0;
};
StandResult standTenSeconds(const std::vector<Body>& bodies) {
  RigidWorld world(gravityField(), {});
  world.state().setSleep({.enabled = false});
  EXPECT_TRUE(world.add(bodies));
  const auto start = world.state().bodies();
  for (int i = 0; i < 1000; ++i) world.step(kDt);
  StandResult r;
  for (std::size_t i = 0; i < start.size(); ++i) {
    const Body& b = world.state().bodies()[i];
    if (b.kinematic) continue;
    r.drift = std::max(r.drift, (asEigen(b.position) - asEigen(start[i].position)).norm());
    r.speed = std::max(r.speed, norm(b.linearVelocity));
    r.tilt = std::max(r.tilt, std::abs(1 - std::abs(b.orientation[3])));
  }
  return r;
}

TEST(RigidPhysics, TwentyBoxPyramidStandsForTenSeconds) {
  // Rows of 6, 5, 4, 3, 2 boxes (20), each row centred on the gaps of the one below, 5 mm apart.
  const double h = 0.25, gap = 0.005;
  std::vector<Body> bodies{ground()};
  std::uint64_t id = 10;
  for (int row = 0; row < 5; ++row) {
    const int count = 6 - row;
    for (int k = 0; k < count; ++k) {
      const double x = (k - 0.5 * (count - 1)) * (2 * h + gap);
      bodies.push_back(makeBody(id++, msg::Shape::box({h, h, h}), 1.0, {x, h + row * 2 * h, 0}));
    }
  }
  ASSERT_EQ(bodies.size(), 21u);
  const StandResult r = standTenSeconds(bodies);
  std::printf("[pyramid] max drift %.3g m, max speed %.3g m/s, max tilt %.3g\n", r.drift, r.speed,
              r.tilt);
  EXPECT_LT(r.drift, 0.01);  // the bound: 1 cm
  EXPECT_LT(r.speed, 1e-3);
  EXPECT_LT(r.tilt, 1e-3);
}

TEST(RigidPhysics, TenBoxTowerStandsForTenSeconds) {
  // Ten 1 kg boxes in one column, 2.5 m tall. (With alternating masses of 1 and 3 kg the top
  // wanders 1.2 cm in 10 s: a known weakness, nodes/rigid/README.md.)
  const double h = 0.125;
  std::vector<Body> bodies{ground()};
  for (int k = 0; k < 10; ++k)
    bodies.push_back(makeBody(static_cast<std::uint64_t>(10 + k), msg::Shape::box({h, h, h}), 1.0,
                              {0, h + k * 2 * h, 0}));
  const StandResult r = standTenSeconds(bodies);
  std::printf("[tower] max drift %.3g m, max speed %.3g m/s, max tilt %.3g\n", r.drift, r.speed,
              r.tilt);
  EXPECT_LT(r.drift, 0.01);
  EXPECT_LT(r.speed, 5e-3);  // it creeps at about 2 mm/s (README, known weaknesses)
  EXPECT_LT(r.tilt, 1e-3);
}

struct RestResult {
  double maxSpeed = 0, maxPenetration = 0, lowest = 1e9, maxAbsXZ = 0;
};

RestResult settleMixed(RigidWorld& world, int steps) {
  auto bodies = generateScene("mixed:20");
  EXPECT_TRUE(bodies);
  EXPECT_TRUE(world.add(*bodies));
  RestResult r;
  for (int i = 0; i < steps; ++i) {
    world.step(kDt);
    if (i >= steps - 50) {  // the last half second: at rest and no jitter
      for (const Body& b : world.state().bodies()) {
        if (b.kinematic) continue;
        r.maxSpeed = std::max(r.maxSpeed, norm(b.linearVelocity) + 0.2 * norm(b.angularVelocity));
      }
    }
    for (const auto& c : world.solver().contacts())
      r.maxPenetration = std::max(r.maxPenetration, -c.distance);
  }
  for (const Body& b : world.state().bodies()) {
    if (b.kinematic) continue;
    const auto box = msg::worldBounds(b.shape, b.position, b.orientation);
    r.lowest = std::min(r.lowest, box.min[1]);
    r.maxAbsXZ = std::max({r.maxAbsXZ, std::abs(b.position[0]), std::abs(b.position[2])});
  }
  return r;
}

TEST(RigidPhysics, TwentyMixedObjectsComeToRestInTheBox) {
  RigidWorld world(gravityField(), {});
  world.state().setSleep({.enabled = false});  // measure the solver's own rest, without sleeping
  const auto r = settleMixed(world, 600);      // 6 s
  std::printf(
      "[mixed] max speed in the last 0.5 s %.3g m/s, worst penetration %.3g m, lowest point %.3g "
      "m\n",
      r.maxSpeed, r.maxPenetration, r.lowest);
  EXPECT_LT(r.maxSpeed, 0.05);
  EXPECT_LT(r.maxPenetration, 0.03);  // over the whole run, impacts included
  EXPECT_GT(r.lowest, -0.01);         // nothing sank through the ground
  EXPECT_LT(r.maxAbsXZ, 1.0);         // nothing left the box through a wall
}

// A concave static triangle mesh (a V-shaped trough) catches a sphere, a box and a moving
// triangle-mesh body (a closed tetrahedron, through GImpact); they settle in the trough's valley.
TEST(RigidPhysics, StaticTriangleMeshCatchesConvexAndMeshBodies) {
  // Two planes meeting along the z axis at y = 0, sloping up to y = 1 at x = +-2.
  std::vector<double> v{-2, 1, -2, -2, 1, 2, 0, 0, -2, 0, 0, 2, 2, 1, -2, 2, 1, 2};
  std::vector<std::uint32_t> t{0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4};
  const auto trough = msg::Shape::triangleMesh(v, t);
  // A closed tetrahedron as a moving mesh.
  const auto tetra =
      msg::Shape::triangleMesh({0.2, -0.1, 0, -0.1, -0.1, 0.17, -0.1, -0.1, -0.17, 0, 0.2, 0},
                               {0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0});
  RigidWorld world(gravityField(), {});
  ASSERT_TRUE(world.add({makeKinematic(1, trough, {0, 0, 0}),
                         makeBody(2, msg::Shape::sphere(0.15), 1.0, {0.8, 1.5, 0}),
                         makeBody(3, msg::Shape::box({0.1, 0.1, 0.1}), 1.0, {-0.6, 1.2, 0.5}),
                         makeBody(4, tetra, 1.0, {0.1, 1.0, -0.8})}));
  for (int i = 0; i < 500; ++i) world.step(kDt);
  for (std::uint64_t id : {2u, 3u, 4u}) {
    const Body& b = *world.state().find(id);
    const auto box = msg::worldBounds(b.shape, b.position, b.orientation);
    // Above the trough's surface y = |x| / 2 at its lowest point, and near the valley.
    EXPECT_GT(box.min[1], -0.02) << id;
    EXPECT_LT(box.min[1], 0.3) << id;
    EXPECT_GT(b.position[1], 0.5 * std::abs(b.position[0])) << id;
    EXPECT_LT(std::abs(b.position[0]), 0.4) << id;
  }
}

// Fast bodies thrown at the demo box's 0.2 m walls stay inside: contacts are found up to 4 cm
// ahead (speculative) and deeper overlaps are still seen by Bullet as penetrations.
TEST(RigidPhysics, FastBodiesDoNotTunnelThroughTheWalls) {
  for (double speed : {5.0, 10.0, 15.0}) {
    auto bodies = generateScene("mixed:1");  // ground, four walls, one sphere
    ASSERT_TRUE(bodies);
    bodies->pop_back();
    Body ball = makeBody(100, msg::Shape::sphere(0.1), 1.0, {0, 0.3, 0});
    ball.linearVelocity = {speed, 0, 0};
    Body box = makeBody(101, msg::Shape::box({0.1, 0.1, 0.1}), 1.0, {0, 0.3, 0.5});
    box.linearVelocity = {0, -2, -speed};
    bodies->push_back(ball);
    bodies->push_back(box);
    RigidWorld world(gravityField(), {});
    ASSERT_TRUE(world.add(*bodies));
    for (int i = 0; i < 200; ++i) {
      world.step(kDt);
      for (std::uint64_t id : {100u, 101u}) {
        const Body& b = *world.state().find(id);
        ASSERT_LT(std::abs(b.position[0]), 1.0) << "speed " << speed << ", step " << i;
        ASSERT_LT(std::abs(b.position[2]), 1.0) << "speed " << speed << ", step " << i;
        ASSERT_GT(b.position[1], 0.0) << "speed " << speed << ", step " << i;
      }
    }
  }
}

TEST(RigidPhysics, SettledBodiesSleepAndWakeWhenHit) {
  RigidWorld world(gravityField(), {});
  const auto r = settleMixed(world, 400);
  EXPECT_EQ(r.maxSpeed, 0.0);
  for (const Body& b : world.state().bodies())
    if (!b.kinematic) {
      EXPECT_TRUE(world.state().asleep(b.id)) << b.id;
    }
  EXPECT_TRUE(world.step(kDt).empty()) << "a settled scene reports no change";
  // A heavy sphere dropped on the pile wakes what it hits.
  ASSERT_TRUE(world.add({makeBody(1000, msg::Shape::sphere(0.2), 20.0, {0, 1.5, 0})}));
  std::set<std::uint64_t> woken;
  for (int i = 0; i < 200; ++i)
    for (const Change& c : world.step(kDt))
      if (c.id != 1000) woken.insert(c.id);
  EXPECT_FALSE(woken.empty());
  const Body& ball = *world.state().find(1000);
  EXPECT_LT(ball.position[1], 1.0);  // it landed on the pile, not in the air
  EXPECT_GT(msg::worldBounds(ball.shape, ball.position, ball.orientation).min[1], -0.01);
}

TEST(RigidPhysics, KinematicBodyNeverMoves) {
  RigidWorld world(gravityField(), {});
  Body platform = makeKinematic(1, msg::Shape::box({1, 0.1, 1}), {0, 0.5, 0},
                                {0, std::sin(0.1), 0, std::cos(0.1)});
  ASSERT_TRUE(
      world.add({platform, makeBody(2, msg::Shape::box({0.2, 0.2, 0.2}), 50.0, {0.3, 1.5, 0}),
                 makeBody(3, msg::Shape::sphere(0.2), 5.0, {-0.3, 2.0, 0.1})}));
  // Forces sent to it are ignored too.
  EXPECT_TRUE(
      world.state().applyForce(1, msg::ForceEvent{{0, 1e6, 0}, {1e6, 0, 0}, {1, 1, 1}, kDt}));
  for (int i = 0; i < 300; ++i) world.step(kDt);
  const Body& p = *world.state().find(1);
  EXPECT_EQ(p.position, platform.position);
  EXPECT_EQ(p.orientation, platform.orientation);
  EXPECT_GT(world.state().find(2)->position[1], 0.6 + 0.15);  // resting on it
  // A kinematic body with a velocity moves with it, whatever hits it.
  RigidAnimatorState state;
  Body mover = makeKinematic(4, msg::Shape::sphere(1), {0, 0, 0});
  mover.linearVelocity = {1, 0, 0};
  ASSERT_TRUE(state.addBody(mover));
  state.applyForce(4, msg::ForceEvent{{-100, 0, 0}, {}, {}, 1.0});
  for (int i = 0; i < 10; ++i) state.step(0.1);
  EXPECT_NEAR(state.find(4)->position[0], 1.0, 1e-12);
}

TEST(RigidPhysics, SameRunTwiceGivesIdenticalBits) {
  std::vector<Body> results[2];
  for (auto& result : results) {
    RigidWorld world(gravityField(), {});
    settleMixed(world, 200);
    result = world.state().bodies();
  }
  ASSERT_EQ(results[0].size(), results[1].size());
  for (std::size_t i = 0; i < results[0].size(); ++i) {
    const Body& a = results[0][i];
    const Body& b = results[1][i];
    EXPECT_EQ(0, std::memcmp(a.position.data(), b.position.data(), sizeof(a.position))) << a.id;
    EXPECT_EQ(0, std::memcmp(a.orientation.data(), b.orientation.data(), sizeof(a.orientation)))
        << a.id;
    EXPECT_EQ(
        0, std::memcmp(a.linearVelocity.data(), b.linearVelocity.data(), sizeof(a.linearVelocity)))
        << a.id;
    EXPECT_EQ(0, std::memcmp(a.angularVelocity.data(), b.angularVelocity.data(),
                             sizeof(a.angularVelocity)))
        << a.id;
  }
}

TEST(RigidPhysics, FreeAsymmetricBodyConservesAngularMomentum) {
  RigidAnimatorState state;
  Body body =
      makeBody(1, msg::Shape::box({0.5, 0.2, 0.1}), 3.0, {0, 0, 0}, {0.1, 0.3, -0.2, 0.927});
  body.angularVelocity = {0.4, 2.0, 0.3};  // near the unstable middle axis: tumbles
  ASSERT_TRUE(state.addBody(body));
  const Eigen::Vector3d l0 = angularMomentum(*state.find(1));
  const double e0 = kineticEnergy(*state.find(1));
  const Vec3 w0 = state.find(1)->angularVelocity;
  for (int i = 0; i < 2000; ++i) state.step(0.001);
  const Body& b = *state.find(1);
  const Eigen::Vector3d l1 = angularMomentum(b);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(l1[k], l0[k], 1e-9 * l0.norm());
  EXPECT_GT((asEigen(b.angularVelocity) - asEigen(w0)).norm(), 0.1)
      << "w should precess for an asymmetric body";
  EXPECT_NEAR(kineticEnergy(b), e0, 0.02 * e0);
  const double qn = asEigen(b.orientation).norm();
  EXPECT_NEAR(qn, 1.0, 1e-12);
}

TEST(RigidPhysics, TorqueUsesTheRotatedInertia) {
  // A body turned 90 degrees about z: its body x axis is the world y axis. A world torque about
  // y meets the body's x inertia.
  RigidAnimatorState state;
  Body body = makeBody(1, msg::Shape::box({0.5, 0.1, 0.2}), 2.0, {0, 0, 0},
                       {0, 0, std::sqrt(0.5), std::sqrt(0.5)});
  ASSERT_TRUE(state.addBody(body));
  const double ixx = body.inertia[0], iyy = body.inertia[4];
  ASSERT_GT(std::abs(ixx - iyy), 0.01);
  const double dt = 1e-3;
  state.applyForce(1, msg::ForceEvent{{0, 0, 0}, {0, 1.0, 0}, {0, 0, 0}, dt});
  state.step(dt);
  EXPECT_NEAR(state.find(1)->angularVelocity[1], dt / ixx, 1e-9);
  EXPECT_NEAR(state.find(1)->angularVelocity[0], 0.0, 1e-9);
  // A force off the centre gives torque (point - position) x force.
  RigidAnimatorState second;
  ASSERT_TRUE(second.addBody(makeBody(2, msg::Shape::sphere(1), 1.0, {1, 2, 3})));
  const double i = second.find(2)->inertia[0];
  second.applyForce(2, msg::ForceEvent{{0, 0, 3}, {0, 0, 0}, {1, 3, 3}, 0.5});  // arm (0,1,0)
  second.step(0.5);
  EXPECT_NEAR(second.find(2)->angularVelocity[0], 1.5 / i, 1e-12);
  EXPECT_NEAR(second.find(2)->linearVelocity[2], 1.5, 1e-12);
}

TEST(RigidPhysics, AnimatorReportsOnlyChangedBodies) {
  RigidAnimatorState state;
  ASSERT_TRUE(state.addBody(makeBody(1, msg::Shape::sphere(1), 1.0, {0, 0, 0})));
  ASSERT_TRUE(state.addBody(makeBody(2, msg::Shape::sphere(1), 1.0, {5, 0, 0})));
  ASSERT_TRUE(state.addBody(makeKinematic(3, msg::Shape::sphere(1), {9, 0, 0})));
  EXPECT_TRUE(state.step(0.01).empty());
  state.applyForce(2, msg::ForceEvent{{1, 0, 0}, {}, {5, 0, 0}, 0.01});
  auto changes = state.step(0.01);
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0].id, 2u);
  EXPECT_TRUE(changes[0].pose && changes[0].velocity);
  changes = state.step(0.01);  // coasting: pose changes, velocity does not
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_TRUE(changes[0].pose);
  EXPECT_FALSE(changes[0].velocity);
  EXPECT_FALSE(state.applyForce(99, msg::ForceEvent{}));
  EXPECT_FALSE(state.addBody(makeBody(1, msg::Shape::sphere(1), 1.0, {0, 0, 0})));
}

TEST(RigidPhysics, ForceFieldTerms) {
  auto field =
      ForceField::parse("gravity 0 -10 0; uniform 1 0 0; attractor 0 0 10 2 0.5; drag 0.5 0.25");
  ASSERT_TRUE(field) << field.error().message;
  FieldTarget t{2.0, {0, 0, 0}, {1, 0, 0}, {0, 4, 0}};
  const auto f = field->forceOn(t, 0.01);
  EXPECT_NEAR(f.force[0], 1 - 0.5, 1e-12);
  EXPECT_NEAR(f.force[1], -20, 1e-12);
  EXPECT_NEAR(f.force[2], 2.0 * 2 / 100, 1e-12);  // m mu / r^2 towards the centre
  EXPECT_NEAR(f.torque[1], -1.0, 1e-12);
  EXPECT_EQ(f.duration, 0.01);
  EXPECT_EQ(field->gravity(), (Vec3{0, -10, 0}));
  t.mass = kInfiniteMass;
  EXPECT_EQ(field->forceOn(t, 0.01).force, (Vec3{0, 0, 0}));
  EXPECT_FALSE(ForceField::parse("gravity 0 1"));
  EXPECT_FALSE(ForceField::parse("magnet 1 2 3"));
  EXPECT_FALSE(ForceField::parse("drag x"));
}

}  // namespace
}  // namespace vrflow::rigid
