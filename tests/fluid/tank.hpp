#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "vrflow/fluid/solver.hpp"

// Small tanks for the tests: a cell size of 5 cm, liquid filling the bottom.
namespace vrflow::fluid::testing {

inline FluidSettings smallTank(int nx, int ny, int nz) {
  FluidSettings s;
  s.nx = nx;
  s.ny = ny;
  s.nz = nz;
  s.cellSize = 0.05;
  return s;
}

inline std::unique_ptr<FluidSolver> makeTank(const FluidSettings& s, double depth) {
  auto solver = FluidSolver::create(s);
  EXPECT_TRUE(solver.ok()) << (solver.ok() ? "" : solver.error().message);
  auto status = (*solver)->addLiquidBox({{0, 0, 0}, {s.nx * s.cellSize, depth, s.nz * s.cellSize}});
  EXPECT_TRUE(status.ok()) << (status.ok() ? "" : status.error().message);
  return std::move(*solver);
}

/// The liquid's surface height: mean of the highest particle plus half the particle spacing in the
/// columns at the four corners' neighbourhoods, away from the centre where the tests put bodies.
inline double cornerLevel(const FluidSolver& solver) {
  const auto b = solver.bounds();
  const double h = solver.settings().cellSize;
  double sum = 0.0;
  int n = 0;
  for (double x : {b.min[0] + 1.5 * h, b.max[0] - 1.5 * h}) {
    for (double z : {b.min[2] + 1.5 * h, b.max[2] - 1.5 * h}) {
      sum += solver.surfaceHeightAt(x, z);
      ++n;
    }
  }
  const int per = solver.settings().particlesPerCell == 27  ? 3
                  : solver.settings().particlesPerCell == 8 ? 2
                                                            : 1;
  return sum / n + 0.5 * h / per;
}

}  // namespace vrflow::fluid::testing
