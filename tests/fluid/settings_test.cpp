#include "vrflow/fluid/settings.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tank.hpp"
#include "vrflow/fluid/solver.hpp"

namespace vrflow::fluid {
namespace {

using testing::smallTank;

std::string createError(const FluidSettings& s) {
  auto solver = FluidSolver::create(s);
  return solver.ok() ? std::string() : solver.error().message;
}

TEST(FluidSettings, DefaultsAreThePapersGridAndValid) {
  FluidSettings s;
  EXPECT_EQ(s.nx, 32);
  EXPECT_EQ(s.ny, 64);
  EXPECT_EQ(s.nz, 32);
  EXPECT_TRUE(validateSettings(s).ok());
}

TEST(FluidSettings, ZeroOrNegativeGridSizesAreRejectedByName) {
  auto s = smallTank(8, 8, 8);
  s.nx = 0;
  EXPECT_NE(createError(s).find("nx = 0"), std::string::npos) << createError(s);
  s = smallTank(8, 8, 8);
  s.nz = -4;
  EXPECT_NE(createError(s).find("nz = -4"), std::string::npos) << createError(s);
  s = smallTank(8, 8, 8);
  s.ny = 5000;
  EXPECT_NE(createError(s).find("between 2 and 1024"), std::string::npos);
}

TEST(FluidSettings, ZeroNegativeOrNonFiniteCellSizeIsRejected) {
  for (double h : {0.0, -0.1, std::numeric_limits<double>::quiet_NaN(),
                   std::numeric_limits<double>::infinity()}) {
    auto s = smallTank(8, 8, 8);
    s.cellSize = h;
    EXPECT_NE(createError(s).find("cell size"), std::string::npos) << h;
  }
}

TEST(FluidSettings, BadMaterialAndSolverKnobsAreRejected) {
  auto s = smallTank(8, 8, 8);
  s.density = 0;
  EXPECT_NE(createError(s).find("density"), std::string::npos);
  s = smallTank(8, 8, 8);
  s.flipRatio = 1.5;
  EXPECT_NE(createError(s).find("flip ratio"), std::string::npos);
  s = smallTank(8, 8, 8);
  s.cgTolerance = 0;
  EXPECT_NE(createError(s).find("CG tolerance"), std::string::npos);
  s = smallTank(8, 8, 8);
  s.particlesPerCell = 5;
  EXPECT_NE(createError(s).find("particles per cell"), std::string::npos);
  s = smallTank(8, 8, 8);
  s.gravity[1] = std::numeric_limits<double>::infinity();
  EXPECT_NE(createError(s).find("gravity"), std::string::npos);
  for (int threads : {0, -1, 65}) {
    s = smallTank(8, 8, 8);
    s.threads = threads;
    EXPECT_NE(createError(s).find("threads " + std::to_string(threads)), std::string::npos);
  }
}

TEST(FluidSettings, PreconditionersAreReadByNameAndOthersAreRefused) {
  for (const auto p : {FluidPreconditioner::kMic0, FluidPreconditioner::kMultigrid}) {
    FluidPreconditioner read = p == FluidPreconditioner::kMic0 ? FluidPreconditioner::kMultigrid
                                                               : FluidPreconditioner::kMic0;
    ASSERT_TRUE(parsePreconditioner(preconditionerName(p), read));
    EXPECT_EQ(read, p);
  }
  EXPECT_EQ(FluidSettings{}.preconditioner, FluidPreconditioner::kMic0);
  FluidPreconditioner read = FluidPreconditioner::kMultigrid;
  for (const char* bad : {"", "MIC0", "jacobi", "multigrid "}) {
    EXPECT_FALSE(parsePreconditioner(bad, read)) << bad;
    EXPECT_EQ(read, FluidPreconditioner::kMultigrid) << bad;
  }
  auto s = smallTank(8, 8, 8);
  s.preconditioner = static_cast<FluidPreconditioner>(7);
  EXPECT_NE(createError(s).find("preconditioner 7"), std::string::npos);
}

TEST(FluidSettings, AbsurdTimeStepsAreRejectedAndNothingMoves) {
  auto tank = testing::makeTank(smallTank(8, 8, 8), 0.2);
  const auto before = tank->particlePositions();
  for (double dt : {0.0, -0.01, 10.0, 0.5, std::numeric_limits<double>::quiet_NaN()}) {
    auto result = tank->step(dt, {});
    ASSERT_FALSE(result.ok()) << dt;
    EXPECT_NE(result.error().message.find("time step"), std::string::npos)
        << result.error().message;
  }
  // 0.5 s with 5 cm cells: gravity alone moves the liquid 49 cells; the message says what fits.
  auto result = tank->step(0.5, {});
  EXPECT_NE(result.error().message.find("use at most"), std::string::npos)
      << result.error().message;
  EXPECT_EQ(tank->particlePositions(), before);
  EXPECT_TRUE(tank->step(0.01, {}).ok());
}

TEST(FluidSettings, TooManyParticlesIsAnErrorNotATruncation) {
  auto s = smallTank(16, 16, 16);
  s.maxParticles = 1000;
  auto solver = FluidSolver::create(s);
  ASSERT_TRUE(solver.ok());
  auto status = (*solver)->addLiquidBox({{0, 0, 0}, {0.8, 0.4, 0.8}});
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("limit of 1000"), std::string::npos);
  EXPECT_EQ((*solver)->particleCount(), 0u);
}

TEST(FluidSettings, BadBodiesAreNamedAndRejected) {
  auto tank = testing::makeTank(smallTank(8, 8, 8), 0.2);
  RigidBody body;
  body.id = 42;
  body.shape = msg::Shape::box({0.05, 0.05, 0.05});
  body.position = {0.2, 0.2, 0.2};
  body.mass = 0.0;
  auto result = tank->step(0.01, {body});
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().message.find("body 42"), std::string::npos) << result.error().message;
  EXPECT_NE(result.error().message.find("mass"), std::string::npos);
  body.mass = 1.0;
  body.linearVelocity[0] = std::numeric_limits<double>::quiet_NaN();
  result = tank->step(0.01, {body});
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().message.find("not finite"), std::string::npos);
  body.linearVelocity[0] = 0;
  body.shape = msg::Shape::box({-0.05, 0.05, 0.05});
  result = tank->step(0.01, {body});
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().message.find("bad shape"), std::string::npos) << result.error().message;
}

}  // namespace
}  // namespace vrflow::fluid
