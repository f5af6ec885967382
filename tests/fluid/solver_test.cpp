#include "vrflow/fluid/solver.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "tank.hpp"

namespace vrflow::fluid {
namespace {

using testing::makeTank;
using testing::smallTank;

// A column of liquid in one corner of the tank (a dam break).
std::unique_ptr<FluidSolver> damBreak(int nx, int ny, int nz, double volumeCorrection = 0.1) {
  auto s = smallTank(nx, ny, nz);
  s.volumeCorrection = volumeCorrection;
  auto solver = std::move(FluidSolver::create(s).value());
  EXPECT_TRUE(solver
                  ->addLiquidBox(
                      {{0, 0, 0}, {0.4 * nx * s.cellSize, 0.6 * ny * s.cellSize, nz * s.cellSize}})
                  .ok());
  return solver;
}

// The projection drives the discrete divergence of liquid cells to the CG residual: with
// |r| <= 1e-6 |b|, the largest cell divergence stays below 1e-4 1/s while velocity gradients
// in a dam break are of order |u| / h ~ 10-40 1/s. Volume control is off: it asks for a
// non-zero divergence on purpose.
TEST(FluidSolver, DivergenceAfterProjectionIsBelowBound) {
  auto solver = damBreak(16, 16, 8, 0.0);
  double worst = 0.0;
  for (int step = 0; step < 60; ++step) {
    ASSERT_TRUE(solver->step(0.01, {}).ok());
    const auto& stats = solver->lastStats();
    EXPECT_TRUE(stats.cgConverged) << "step " << step << " residual " << stats.cgResidual;
    EXPECT_LE(stats.cgResidual, 1e-6);
    worst = std::max(worst, solver->maxDivergence());
  }
  std::printf("max divergence over 60 dam-break steps: %.3g 1/s, max speed %.3f m/s\n", worst,
              solver->maxParticleSpeed());
  EXPECT_LT(worst, 1e-4);
  EXPECT_GT(solver->maxParticleSpeed(), 0.5);  // the dam did break: the check is not vacuous
}

// A tank at rest: hydrostatic pressure balances gravity; particle jitter may stir it a little.
TEST(FluidSolver, StillTankStaysStillFor500Steps) {
  auto tank = makeTank(smallTank(12, 12, 12), 0.3);
  const double volume0 = tank->liquidVolume();
  double worst = 0.0;
  for (int step = 0; step < 500; ++step) {
    ASSERT_TRUE(tank->step(0.01, {}).ok());
    worst = std::max(worst, tank->maxParticleSpeed());
  }
  std::printf("still tank: max particle speed over 500 steps %.3g m/s, volume %.4f -> %.4f\n",
              worst, volume0, tank->liquidVolume());
  EXPECT_LT(worst, 1e-3);
  EXPECT_NEAR(tank->liquidVolume(), volume0, 0.01 * volume0);
}

// The liquid's volume, estimated from the particles and the particle density of interior cells
// (FluidSolver::liquidVolume: particles that clump or drift apart change it; without volume
// control it drifted by 5-9 % here): a dam of 8 x 12 x 6 cells breaks and sloshes for 1000
// steps (10 s) in a 16 x 16 x 6 tank; checked at the end (right after the break, while few
// interior cells remain, the estimate swings by up to ~5 %, printed).
TEST(FluidSolver, VolumeIsConservedWithin2PercentOver1000Steps) {
  auto s = smallTank(16, 16, 6);
  // VRFLOW_FLUID_VOLUME_CORRECTION=0 shows the check failing without volume control (+3.3 %).
  if (const char* vc = std::getenv("VRFLOW_FLUID_VOLUME_CORRECTION"))
    s.volumeCorrection = std::atof(vc);
  auto solver = std::move(FluidSolver::create(s).value());
  ASSERT_TRUE(
      solver->addLiquidBox({{0, 0, 0}, {8 * s.cellSize, 12 * s.cellSize, 6 * s.cellSize}}).ok());
  const double volume0 = solver->liquidVolume();
  double worst = 0.0;
  for (int step = 0; step < 1000; ++step) {
    ASSERT_TRUE(solver->step(0.01, {}).ok());
    worst = std::max(worst, std::abs(solver->liquidVolume() - volume0) / volume0);
  }
  const double final = solver->liquidVolume();
  std::printf("volume %.5f -> %.5f m^3 (%.2f %%), largest deviation over the 1000 steps %.2f %%\n",
              volume0, final, 100.0 * (final - volume0) / volume0, 100.0 * worst);
  EXPECT_NEAR(final, volume0, 0.02 * volume0);
}

TEST(FluidSolver, SameInputsGiveTheSameBits) {
  auto a = damBreak(12, 12, 6);
  auto b = damBreak(12, 12, 6);
  for (int step = 0; step < 30; ++step) {
    ASSERT_TRUE(a->step(0.01, {}).ok());
    ASSERT_TRUE(b->step(0.01, {}).ok());
  }
  EXPECT_EQ(a->particlePositions(), b->particlePositions());
}

// Threads inside a block take runs of planes (transfers, extrapolation) or of particles
// (advection); sums at the runs' borders keep the serial order, so the thread count changes no
// bit. A dam break with a floating and a sinking box in it (forces, pushing particles out), 16
// planes: 2 and 3 threads cut it into 2 and 3 runs, 8 threads into 4 (runs are at least 4
// planes).
TEST(FluidSolver, AnyThreadCountGivesTheSameBitsAsOneThread) {
  std::vector<float> positions[4];
  std::vector<BodyForce> forces[4];
  const int threadCounts[4] = {1, 2, 3, 8};
  for (int t = 0; t < 4; ++t) {
    auto s = smallTank(16, 12, 16);
    s.threads = threadCounts[t];
    auto solver = std::move(FluidSolver::create(s).value());
    ASSERT_TRUE(solver->addLiquidBox({{0, 0, 0}, {0.5, 0.35, 0.8}}).ok());
    std::vector<RigidBody> bodies(2);
    for (int b = 0; b < 2; ++b) {
      bodies[b].id = static_cast<std::uint64_t>(b + 1);
      bodies[b].shape = msg::Shape::box({0.06, 0.06, 0.06});
      bodies[b].position = {0.2, b == 0 ? 0.26 : 0.15, 0.2 + 0.4 * b};
      bodies[b].mass = (b == 0 ? 500.0 : 2000.0) * 0.12 * 0.12 * 0.12;
    }
    for (int step = 0; step < 25; ++step) {
      auto f = solver->step(0.01, bodies);
      ASSERT_TRUE(f.ok());
      forces[t] = *f;
    }
    positions[t] = solver->particlePositions();
  }
  for (int t = 1; t < 4; ++t) {
    EXPECT_EQ(positions[t], positions[0]) << threadCounts[t] << " threads";
    for (int b = 0; b < 2; ++b) {
      EXPECT_EQ(forces[t][static_cast<std::size_t>(b)].force,
                forces[0][static_cast<std::size_t>(b)].force)
          << threadCounts[t] << " threads, box " << b;
    }
  }
  // The boxes were wet: the comparison covers the coupling.
  EXPECT_NE(forces[0][0].force[1], 0.0);
  EXPECT_NE(forces[0][1].force[1], 0.0);
}

}  // namespace
}  // namespace vrflow::fluid
