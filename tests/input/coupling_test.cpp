// The haptic loop in one process, as the network runs it: the simulated arm (1 kHz, its force
// held over each tick), the virtual coupling and the tool, and the rigid package's contact
// solver at 100 Hz whose force on the tool is held over ten ticks (what the repeat filter does).
#include "vrflow/input/coupling.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "vrflow/input/simulated_arm.hpp"
#include "vrflow/rigid/contact_solver.hpp"

namespace vrflow::input {
namespace {

constexpr double kPeriod = 0.001;
constexpr int kTicksPerPhysicsStep = 10;
constexpr double kToolRadius = 0.05;

/// The energy books of one run.
struct Books {
  double maxGenerated = -1e300;  ///< max over time of stored(t) - stored(0) - work supplied
  double maxStored = 0.0;
  double finalStored = 0.0;
  double userWork = 0.0;
  msg::Vec3 meanFeedback{};  ///< over the last second
  msg::Vec3 meanContact{};
  msg::Vec3 armPosition{};
  msg::Vec3 target{};
  double maxThirdLawError = 0.0;  ///< |feedback + coupling force on the tool|, every tick
};

/// Runs the loop for `seconds` with the hand following `keys`; with a ground (a static box whose
/// top is y = 0) when `ground`.
Books run(const std::string& keys, const CouplingParams& params, const DeviceOptions& arm,
          double seconds, bool ground) {
  auto track = KeyframeTrack::parse(keys, "keys");
  EXPECT_TRUE(track) << track.error().message;
  auto created = SimulatedArm::create(*track, arm);
  EXPECT_TRUE(created);
  SimulatedArm& device = **created;
  rigid::ContactParams contactParams;
  contactParams.gravity = {0, 0, 0};
  rigid::RigidContactSolver solver(contactParams);
  const std::uint64_t groundId = 1, toolId = 2;
  if (ground) {
    EXPECT_TRUE(
        solver.setBody(rigid::makeKinematic(groundId, msg::Shape::box({2, 0.5, 2}), {0, -0.5, 0})));
  }
  auto start = device.sample(0.0);
  HapticTool tool(params, start->position);
  auto body =
      rigid::makeBody(toolId, msg::Shape::sphere(kToolRadius), params.toolMass, start->position);
  EXPECT_TRUE(solver.setBody(body));

  auto stored = [&](const DeviceSample& s) {
    return device.kineticEnergy() + tool.energy(s.position);
  };
  Books books;
  const double initial = stored(*start);
  double contactWork = 0.0;
  msg::Vec3 contact{};
  const auto ticks = static_cast<long>(std::lround(seconds / kPeriod));
  const long averaged = static_cast<long>(std::lround(1.0 / kPeriod));
  for (long tick = 0; tick < ticks; ++tick) {
    const double time = static_cast<double>(tick) * kPeriod;
    if (tick % kTicksPerPhysicsStep == 0) {
      solver.setState(toolId, tool.position(), {0, 0, 0, 1}, tool.velocity(), {0, 0, 0});
      contact = {};
      for (const auto& [id, event] : solver.solve(kPeriod * kTicksPerPhysicsStep))
        if (id == toolId) contact = event.force;
    }
    const auto sample = device.sample(time);
    const msg::Vec3 before = tool.position();
    const msg::Vec3 feedback = tool.step(*sample, contact);
    device.render(feedback, kPeriod);
    for (int k = 0; k < 3; ++k) {
      contactWork += contact[k] * (tool.position()[k] - before[k]);
      books.maxThirdLawError =
          std::max(books.maxThirdLawError, std::abs(feedback[k] + tool.couplingForce()[k]));
      if (tick >= ticks - averaged) {
        books.meanFeedback[k] += feedback[k] / static_cast<double>(averaged);
        books.meanContact[k] += contact[k] / static_cast<double>(averaged);
      }
    }
    const auto after = device.sample(time + kPeriod);
    const double now = stored(*after);
    books.maxStored = std::max(books.maxStored, now);
    books.maxGenerated =
        std::max(books.maxGenerated, now - initial - device.userWork() - contactWork);
    books.finalStored = now;
    books.armPosition = after->position;
  }
  books.userWork = device.userWork();
  books.target = track->at(seconds).position;
  return books;
}

/// A minute of a hand that presses the tool into the ground and scrubs it around, in and out of
/// contact (60 keys, one per second).
std::string scrubbing() {
  std::ostringstream keys;
  for (int i = 0; i <= 60; ++i) {
    const double depth = (i % 3 == 2) ? 0.2 : -0.03 * (1 + i % 4);  // every third key lifts off
    keys << i << " " << 0.3 * std::sin(0.7 * i) << " " << depth << " " << 0.3 * std::cos(1.3 * i)
         << "\n";
  }
  return keys.str();
}

TEST(HapticCoupling, StiffnessRangeIsTheCouplingsAndThePhysicsBoundAndBeyondItIsRefused) {
  CouplingParams params;  // c = 2 N s/m, T = 1 ms, m = 0.2 kg, physics step 10 ms
  EXPECT_DOUBLE_EQ(maxPassiveStiffness(params), 4000.0);  // 2 c / T
  params.damping = 6.0;
  EXPECT_DOUBLE_EQ(maxPassiveStiffness(params), 8000.0);  // 4 m / dt^2
  params.damping = 2.0;
  params.stiffness = 4000.0;
  EXPECT_TRUE(checkCoupling(params));
  params.stiffness = 4001.0;
  const auto refused = checkCoupling(params);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find(
                "stiffness 4001 N/m is outside the passive range (0, min(2 c / T, 4 m / dt^2)] = "
                "(0, 4000] for damping c = 2 N s/m, dt T = 0.001 s, tool-mass m = 0.2 kg, "
                "physics-dt dt = 0.01 s"),
            std::string::npos)
      << refused.error().message;
  params.stiffness = 100.0;
  params.toolMass = 0.0;
  EXPECT_FALSE(checkCoupling(params));
}

// Over 60 s of simulated time, for stiffnesses across the documented range (and a device with
// or without damping of its own), the energy stored in the hand, the tool and the coupling
// never exceeds what the user's hand and the contacts put in by more than 1e-5 of it (the
// coupling generates nothing beyond the one-tick lag of its held spring, O(T^2)), and the
// whole loop, contacts included, stays bounded.
TEST(HapticCoupling, LoopStaysPassiveOverSixtySecondsAcrossTheStiffnessRange) {
  for (const double armDamping : {4.0, 0.0}) {
    DeviceOptions arm;  // M 0.5 kg, grip 400 N/m
    arm.armDamping = armDamping;
    for (const double fraction : {0.05, 0.5, 1.0}) {
      for (const double damping : {0.5, 2.0, 6.0}) {
        CouplingParams params;
        params.damping = damping;
        params.stiffness = fraction * maxPassiveStiffness(params);
        const Books books = run(scrubbing(), params, arm, 60.0, true);
        SCOPED_TRACE("k = " + std::to_string(params.stiffness) +
                     ", c = " + std::to_string(damping) + ", b = " + std::to_string(armDamping));
        EXPECT_GT(books.userWork, 10.0);  // the user did put energy in
        EXPECT_LE(books.maxGenerated, 1e-5 * books.userWork);
        EXPECT_LT(books.maxStored, 5.0);
      }
    }
  }
}

// The same books catch an active coupling: at twice and four times 2 c / T (still under the
// physics bound), energy appears that nobody put in.
TEST(HapticCoupling, BooksCatchTheEnergyGrowthOfACouplingBeyondTheBound) {
  DeviceOptions arm;
  for (const double fraction : {2.0, 4.0}) {
    CouplingParams params;
    params.damping = 1.0;
    params.stiffness = fraction * maxPassiveStiffness(params);
    const Books books = run(scrubbing(), params, arm, 60.0, true);
    EXPECT_FALSE(books.maxGenerated <= 1e-5 * books.userWork) << "k = " << params.stiffness;
  }
}

// Pressing the tool onto the ground: once settled, the force rendered on the hand equals the
// contact force on the tool (the reaction the coupling carries), and holds the user's grip:
// feedback = grip stiffness x (hand - target). Every tick, the feedback is minus the coupling
// force on the tool.
TEST(HapticCoupling, FeedbackForceEqualsTheReactionOnTheTool) {
  DeviceOptions arm;
  CouplingParams params;
  const Books books = run("0 0 0.2 0\n1 0 -0.05 0\n", params, arm, 4.0, true);
  EXPECT_EQ(books.maxThirdLawError, 0.0);
  EXPECT_GT(books.meanContact[1], 10.0);  // the ground pushes up
  EXPECT_NEAR(books.meanFeedback[1], books.meanContact[1], 0.01 * books.meanContact[1]);
  EXPECT_NEAR(books.meanFeedback[1], arm.armStiffness * (books.armPosition[1] - books.target[1]),
              0.01 * books.meanContact[1]);
  EXPECT_NEAR(books.meanFeedback[0], 0.0, 1e-3 * books.meanContact[1]);
}

}  // namespace
}  // namespace vrflow::input
