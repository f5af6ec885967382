// Rigid / net contact solved with the net's nodes in one velocity solve (issue 26, item 4): a
// heavy box dropped from 2 m is caught by the 8 kg net, a fast small ball does not pass between
// its nodes, momentum is exchanged exactly, a light box rests as before. The rigid is integrated
// here from the ForceEvents rigidContacts returns (what the rigid animator does).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include "rigid_harness.hpp"
#include "vrflow/massspring/contact.hpp"
#include "vrflow/massspring/solver.hpp"

namespace vrflow::massspring {
namespace {

const Vec3 kGravity{0, -9.81, 0};

// The paper scene's net: 20 x 20 nodes 0.1 m apart, 8 kg, k 300 N/m, limit 1.1, corners pinned
// at y = 0.95 (the animator's defaults otherwise: 10 ms steps, 10 sub-steps).
GridParams paperNet() {
  GridParams grid;
  grid.mass = 8.0;
  grid.stiffness = 300.0;
  grid.damping = 0.2;
  grid.origin = {0, 0.95, 0};
  return grid;
}

struct Trial {
  Net net;
  Box body;
  std::size_t contacts = 0;
  double worstLimit = 0;  // largest length / limit of a limited spring over the run
};

// One step of the net (id 1) under the contact forces of `forces`; returns the force event on
// the body (id 2), if any.
const msg::ForceEvent* stepNet(Net& net, const ContactForces& forces, const StepOptions& options) {
  const auto onNet = forces.nodeForces.find(1);
  step(net,
       onNet == forces.nodeForces.end() ? std::span<const double>{}
                                        : std::span<const double>(onNet->second),
       options);
  const auto onBody = forces.rigidForces.find(2);
  return onBody == forces.rigidForces.end() ? nullptr : &onBody->second;
}

// Steps the net and the body together for `steps` 10 ms steps, calling `watch` after each.
Trial simulate(const GridParams& grid, Box body, int steps, bool collide,
               const std::function<void(const Trial&, int)>& watch = {}, int settle = 0) {
  Trial r{*generateGrid(grid), std::move(body)};
  StepOptions options;
  options.gravity = kGravity;
  for (int s = 0; s < settle; ++s) step(r.net, {}, options);  // the net alone first
  ContactParams contact;
  contact.dt = options.dt;
  ContactMemory memory;
  std::map<std::uint64_t, Net> nets;
  std::map<std::uint64_t, RigidBody> rigids;
  for (int s = 0; s < steps; ++s) {
    nets[1] = r.net;
    rigids[2] = r.body.body;
    const auto forces = collide ? rigidContacts(nets, rigids, contact, &memory) : ContactForces{};
    r.contacts += forces.contacts;
    integrate(r.body, stepNet(r.net, forces, options), kGravity, options.dt);
    r.worstLimit = std::max(r.worstLimit, maxConstraintRatio(r.net));
    if (watch) watch(r, s);
  }
  return r;
}

double speedOf(const RigidBody& body) {
  const auto& v = body.linearVelocity;
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

// The deepest net node inside the body (most negative signed distance; 0 if none inside).
double deepestNode(const Trial& r) {
  double deepest = 0;
  const auto& b = r.body.body;
  for (std::size_t i = 0; i < r.net.nodeCount(); ++i) {
    const auto x = r.net.position(i);
    const auto local = msg::rotateInverse(
        b.orientation, {x[0] - b.position[0], x[1] - b.position[1], x[2] - b.position[2]});
    deepest = std::min(deepest, msg::signedDistance(b.shape, local).distance);
  }
  return deepest;
}

TEST(RigidNetContact, HeavyBoxDroppedFromTwoMetresIsCaughtByTheEightKilogramNet) {
  // A 10 kg, 0.3 m box, its bottom 2 m above the net, a little off centre and tilted.
  Box box = makeBox({0.15, 0.15, 0.15}, 10.0, {0.07, 0.95 + 2.0 + 0.15, -0.04});
  const double angle = 0.2;
  box.body.orientation = {std::sin(angle / 2), 0, 0, std::cos(angle / 2)};
  double lowestAboveSurface = 1e300, deepest = 0, lowest = 1e300;

  const auto r = simulate(paperNet(), box, 600, true, [&](const Trial& run, int) {
    const auto& p = run.body.body.position;
    const double surface = surfaceHeight(run.net, p[0], p[2]);
    if (!std::isnan(surface)) lowestAboveSurface = std::min(lowestAboveSurface, p[1] - surface);
    deepest = std::min(deepest, deepestNode(run));
    lowest = std::min(lowest, lowestCorner(run.body));
  });
  std::printf(
      "10 kg box from 2 m: centre at least %.4f m above the net's surface under it, deepest node "
      "%.4f m inside, lowest corner %.3f m, rests at y %.4f, speed %.2e m/s after 6 s, largest "
      "length/limit %.12f\n",
      lowestAboveSurface, deepest, lowest, r.body.body.position[1], speedOf(r.body.body),
      r.worstLimit);
  EXPECT_GT(r.contacts, 0u);
  EXPECT_GT(lowestAboveSurface, 0.1);  // the centre (half-size 0.15) stays above the surface
  EXPECT_GT(deepest, -0.05);
  EXPECT_LT(speedOf(r.body.body), 0.05);
  EXPECT_GT(deepestNode(r), -0.01);  // at rest: on the net, not in it
  EXPECT_LE(r.worstLimit, 1 + 1e-9);
}

TEST(RigidNetContact, WithoutContactTheHeavyBoxFallsThroughTheNet) {
  const Box box = makeBox({0.15, 0.15, 0.15}, 10.0, {0.07, 3.1, -0.04});
  const auto r = simulate(paperNet(), box, 200, false);
  EXPECT_LT(r.body.body.position[1], 0.0);
}

// A 0.5 kg ball of radius 3 cm (smaller than the net's 10 cm cells) thrown down at 10 m/s over
// the middle of a cell of the net hanging at rest: it must not pass between the nodes.
Trial throwBall(bool collide, double& lowestAboveSurface) {
  Box ball = makeBox({}, 0.5, {0.0, 1.3, 0.0});
  ball.body.shape = msg::Shape::sphere(0.03);
  ball.inertia = msg::massProperties(ball.body.shape, 0.5).inertia;
  ball.body.linearVelocity = {0, -10, 0};
  lowestAboveSurface = 1e300;
  return simulate(
      paperNet(), ball, 300, collide,
      [&](const Trial& run, int) {
        const auto& p = run.body.body.position;
        const double surface = surfaceHeight(run.net, p[0], p[2]);
        if (!std::isnan(surface)) lowestAboveSurface = std::min(lowestAboveSurface, p[1] - surface);
      },
      200);
}

TEST(RigidNetContact, FastSmallBallDoesNotPassBetweenTheNodes) {
  double lowest = 0;
  const auto r = throwBall(true, lowest);
  std::printf(
      "ball at 10 m/s: centre at least %.4f m above the net's surface, rests at y %.4f, "
      "speed %.2e m/s after 3 s\n",
      lowest, r.body.body.position[1], speedOf(r.body.body));
  EXPECT_GT(r.contacts, 0u);
  EXPECT_GT(lowest, 0.0);  // the centre never below the surface
  EXPECT_LT(speedOf(r.body.body), 0.05);
  EXPECT_LE(r.worstLimit, 1 + 1e-9);
  double fallen = 0;
  const auto free = throwBall(false, fallen);
  EXPECT_LT(fallen, 0.0);  // without the contacts it goes through
  EXPECT_LT(free.body.body.position[1], 0.0);
}

TEST(RigidNetContact, MomentumExchangedEqualsGravityImpulse) {
  // A free net without limits (no pins, no lock: every impulse goes to both sides) and a 2 kg box
  // thrown down onto it at 5 m/s: over 1 s, the momentum of box and net together changes by the
  // impulse of gravity alone; the net's own changes by more (the contact's share).
  GridParams grid = paperNet();
  grid.pinCorners = false;
  grid.maxStretch = 0;
  Box box = makeBox({0.15, 0.15, 0.15}, 2.0, {0.07, 1.3, -0.04});
  box.body.linearVelocity = {0, -5, 0};
  auto momentum = [](const Net& net) {
    Vec3 p{};
    for (std::size_t i = 0; i < net.nodeCount(); ++i)
      for (int k = 0; k < 3; ++k) p[k] += net.masses[i] * net.velocities[3 * i + k];
    return p;
  };
  const Net start = *generateGrid(grid);
  const auto startNet = momentum(start);
  const auto r = simulate(grid, box, 100, true);
  const auto endNet = momentum(r.net);
  const double time = 1.0, total = grid.mass + 2.0;
  for (int k = 0; k < 3; ++k) {
    const double change = endNet[k] - startNet[k] +
                          2.0 * (r.body.body.linearVelocity[k] - box.body.linearVelocity[k]);
    EXPECT_NEAR(change, total * kGravity[k] * time, 1e-9) << k;
  }
  EXPECT_GT(r.contacts, 0u);
  // The net received the contact's momentum: more than gravity's 8 kg x 9.81 m/s downwards.
  EXPECT_LT(endNet[1] - startNet[1], grid.mass * kGravity[1] * time - 1.0);
}

// A haptic tool (examples/interactive): a 0.2 kg ball of radius 12 cm held by a 2000 N/m,
// 2 N s/m virtual coupling to a hand that goes down 6 cm into the hanging net and stays there.
// The tool is integrated at 1 kHz under the coupling, gravity and the contact force of the last
// 10 ms step (what the haptic module does behind a repeat filter). The coupling's force (~13 N)
// moves the light tool by 0.65 m/s per step: a contact solve blind to it let the tool sink
// through the net and then pulled it down (issue 26).
TEST(RigidNetContact, HapticToolPressedByAStiffCouplingStaysOnTheNet) {
  const double mass = 0.2, radius = 0.12, stiffness = 2000, damping = 2, tick = 0.001;
  Trial r{*generateGrid(paperNet()), makeBox({}, mass, {0.95, 1.4, 0.95})};
  r.body.body.shape = msg::Shape::sphere(radius);
  StepOptions options;
  options.gravity = kGravity;
  for (int s = 0; s < 200; ++s) step(r.net, {}, options);  // the net hangs at rest
  const double surface = surfaceHeight(r.net, 0.95, 0.95);
  const double bottom = surface + radius - 0.06;  // the hand's lowest point
  ContactParams contact;
  contact.dt = options.dt;
  ContactMemory memory;
  std::map<std::uint64_t, Net> nets;
  std::map<std::uint64_t, RigidBody> rigids;
  Vec3 held{};  // the contact force on the tool over the current step
  double x = 1.4, v = 0, lowest = 1e300, weakest = 1e300;
  for (int s = 0; s < 200; ++s) {
    for (int t = 0; t < 10; ++t) {
      const double time = (10 * s + t) * tick;
      const double hand = time < 1.0 ? 1.4 + (bottom - 1.4) * time : bottom;
      const double handSpeed = time < 1.0 ? bottom - 1.4 : 0.0;
      const double a =
          (stiffness * (hand - x) + damping * (handSpeed - v) + held[1]) / mass + kGravity[1];
      x += tick * v + 0.5 * tick * tick * a;
      v += tick * a;
    }
    r.body.body.position[1] = x;
    r.body.body.linearVelocity[1] = v;
    nets[1] = r.net;
    rigids[2] = r.body.body;
    const auto forces = rigidContacts(nets, rigids, contact, &memory);
    const auto* onBody = stepNet(r.net, forces, options);
    held = onBody ? onBody->force : Vec3{};
    if (s >= 150) {  // pressed and settled
      lowest = std::min(lowest, x - surfaceHeight(r.net, 0.95, 0.95));
      weakest = std::min(weakest, held[1]);
    }
  }
  std::printf(
      "haptic tool: centre at least %.4f m above the net under it, contact force at "
      "least %.2f N up while pressed\n",
      lowest, weakest);
  EXPECT_GT(lowest, 0.5 * radius);  // on the net, its centre well above it
  // The net holds the tool against the coupling's pull (2000 N/m x up to 6 cm, less its weight).
  EXPECT_GT(weakest, 5.0);
}

TEST(RigidNetContact, LightBoxStillRestsOnTheNet) {
  // A 0.3 m box of density 40 (1.08 kg), the paper scene's old net objects, dropped 0.3 m.
  const Box box = makeBox({0.15, 0.15, 0.15}, 0.027 * 40, {0.07, 0.95 + 0.3 + 0.15, -0.04});
  double lowestAboveSurface = 1e300, deepest = 0;
  const auto r = simulate(paperNet(), box, 400, true, [&](const Trial& run, int) {
    const auto& p = run.body.body.position;
    const double surface = surfaceHeight(run.net, p[0], p[2]);
    if (!std::isnan(surface)) lowestAboveSurface = std::min(lowestAboveSurface, p[1] - surface);
    deepest = std::min(deepest, deepestNode(run));
  });
  std::printf(
      "light box: centre at least %.4f m above the surface, deepest node %.4f m, rests "
      "at y %.4f, speed %.2e m/s after 4 s\n",
      lowestAboveSurface, deepest, r.body.body.position[1], speedOf(r.body.body));
  EXPECT_GT(lowestAboveSurface, 0.13);
  EXPECT_GT(deepest, -0.02);
  EXPECT_LT(speedOf(r.body.body), 0.02);
  EXPECT_LE(r.worstLimit, 1 + 1e-9);
}

}  // namespace
}  // namespace vrflow::massspring
