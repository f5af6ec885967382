#include "pressure.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "multigrid.hpp"
#include "parallel.hpp"

// The pressure CG on its own: a variable-coefficient Poisson system on an irregular set of
// unknowns (air pockets, rows with gaps, rows and planes with none), as the projection builds
// it. The preconditioner's sweeps can run rows one at a time or in pairs, the second row a cell
// behind the first; both must give the same bits, and the answer must solve the system. The
// multigrid preconditioner must be symmetric and positive definite (or the CG is not valid),
// need several times fewer iterations than MIC(0), and give the same bits on any thread count.
namespace vrflow::fluid::detail {
namespace {

struct Problem {
  Grid grid;
  PressureSystem system;
  std::vector<double> b;
};

// A grid of nx x ny x nz cells with an all-zero system and right-hand side.
Problem zeroProblem(int nx, int ny, int nz) {
  Problem pr;
  pr.grid.nx = nx;
  pr.grid.ny = ny;
  pr.grid.nz = nz;
  const std::size_t n = pr.grid.cells();
  for (auto* v : {&pr.system.diag, &pr.system.ax, &pr.system.ay, &pr.system.az, &pr.b}) {
    v->assign(n, 0.0);
  }
  return pr;
}

Problem irregularProblem(int nx, int ny, int nz, unsigned seed) {
  Problem pr = zeroProblem(nx, ny, nz);
  const Grid& g = pr.grid;
  const std::size_t n = g.cells();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<char> unknown(n, 0);
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        // Liquid below a wavy surface, with scattered air cells; row j = 3 and plane k = 2 are
        // all air.
        const bool below = j < ny - 2 - (i + k) % 3;
        unknown[g.cell(i, j, k)] = below && j != 3 && k != 2 && unit(rng) > 0.15;
      }
    }
  }
  auto& A = pr.system;
  const std::size_t stride[3] = {1, static_cast<std::size_t>(nx),
                                 static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny)};
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const std::size_t c = g.cell(i, j, k);
        if (!unknown[c]) continue;
        pr.b[c] = unit(rng) - 0.5;
        const int idx[3] = {i, j, k};
        const int dims[3] = {nx, ny, nz};
        for (int a = 0; a < 3; ++a) {
          if (idx[a] + 1 >= dims[a]) continue;  // wall: no coupling
          const std::size_t m = c + stride[a];
          const double beta = 0.5 + unit(rng);
          if (unknown[m]) {
            A.diag[c] += beta;
            A.diag[m] += beta;
            (a == 0 ? A.ax : a == 1 ? A.ay : A.az)[c] = -beta;
          } else {
            A.diag[c] += 2.0 * beta;  // air: p = 0 half a cell away
          }
        }
        A.diag[c] += 0.05;  // air next to every cell keeps the system definite
      }
    }
  }
  return pr;
}

// A tank as the projection builds it: liquid below a surface at 0.6 of the height, air above it
// (p = 0 half a cell above the last liquid cell), walls all round (no coupling), one density but
// for a slab of heavier cells (a body, three times the density), a random right-hand side. Its
// only Dirichlet condition is the surface: a Poisson matrix whose condition grows with the size.
Problem tankProblem(int nx, int ny, int nz, unsigned seed) {
  Problem pr = zeroProblem(nx, ny, nz);
  const Grid& g = pr.grid;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const int surface = ny * 3 / 5;
  const auto density = [&](int i, int j, int k) {
    return (i > nx / 3 && i < nx / 2 && j > surface / 3 && j < surface / 2 && k > nz / 4) ? 3.0
                                                                                          : 1.0;
  };
  auto& A = pr.system;
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < surface; ++j) {
      for (int i = 0; i < nx; ++i) {
        const std::size_t c = g.cell(i, j, k);
        pr.b[c] = unit(rng);
        const int idx[3] = {i, j, k};
        const int dims[3] = {nx, j + 1 < surface ? ny : surface + 1, nz};
        for (int a = 0; a < 3; ++a) {
          if (idx[a] + 1 >= dims[a]) continue;  // a wall: no coupling
          const int next[3] = {i + (a == 0), j + (a == 1), k + (a == 2)};
          const double beta = 2.0 / (density(i, j, k) + density(next[0], next[1], next[2]));
          if (a == 1 && j + 1 == surface) {
            A.diag[c] += 2.0 * beta;  // air above: p = 0 half a cell away
            continue;
          }
          A.diag[c] += beta;
          A.diag[c + (a == 0 ? 1 : a == 1 ? g.nx : g.nx * g.ny)] += beta;
          (a == 0 ? A.ax : a == 1 ? A.ay : A.az)[c] = -beta;
        }
      }
    }
  }
  return pr;
}

std::vector<double> solve(const Problem& pr, int rowsPerWave, PcgOutcome& outcome,
                          FluidPreconditioner preconditioner = FluidPreconditioner::kMic0,
                          const Workers* workers = nullptr) {
  PcgWorkspace work;
  work.rowsPerWave = rowsPerWave;
  work.preconditioner = preconditioner;
  work.workers = workers;
  std::vector<double> p;
  outcome = solvePressure(pr.grid, pr.system, pr.b, p, 1e-10, 500, nullptr, work);
  // A second solve reuses the workspace (only the last solve's rows are cleared).
  std::vector<double> again;
  const auto second = solvePressure(pr.grid, pr.system, pr.b, again, 1e-10, 500, nullptr, work);
  EXPECT_EQ(second.iterations, outcome.iterations);
  EXPECT_EQ(std::memcmp(again.data(), p.data(), p.size() * sizeof(double)), 0);
  return p;
}

double relativeResidual(const Problem& pr, const std::vector<double>& p) {
  const Grid& g = pr.grid;
  const auto& A = pr.system;
  const std::size_t sy = static_cast<std::size_t>(g.nx), sz = sy * static_cast<std::size_t>(g.ny);
  double rr = 0.0, bb = 0.0;
  for (int k = 0; k < g.nz; ++k) {
    for (int j = 0; j < g.ny; ++j) {
      for (int i = 0; i < g.nx; ++i) {
        const std::size_t c = g.cell(i, j, k);
        if (A.diag[c] == 0.0) continue;
        double ap = A.diag[c] * p[c];
        if (i + 1 < g.nx) ap += A.ax[c] * p[c + 1];
        if (i > 0) ap += A.ax[c - 1] * p[c - 1];
        if (j + 1 < g.ny) ap += A.ay[c] * p[c + sy];
        if (j > 0) ap += A.ay[c - sy] * p[c - sy];
        if (k + 1 < g.nz) ap += A.az[c] * p[c + sz];
        if (k > 0) ap += A.az[c - sz] * p[c - sz];
        rr += (pr.b[c] - ap) * (pr.b[c] - ap);
        bb += pr.b[c] * pr.b[c];
      }
    }
  }
  return std::sqrt(rr / bb);
}

TEST(PressureCg, RowsSweptInPairsGiveTheBitsOfRowsSweptOneAtATime) {
  // Odd and even row lengths and row counts, so pairs end mid-plane and single rows are left.
  for (const auto& dims :
       {std::array<int, 3>{13, 10, 7}, std::array<int, 3>{8, 9, 6}, std::array<int, 3>{4, 5, 5}}) {
    const Problem pr = irregularProblem(dims[0], dims[1], dims[2], 7u + dims[0]);
    PcgOutcome single, paired;
    const auto p1 = solve(pr, 1, single);
    const auto p2 = solve(pr, 2, paired);
    ASSERT_TRUE(single.converged) << dims[0];
    EXPECT_GT(single.iterations, 5);
    EXPECT_EQ(paired.iterations, single.iterations);
    EXPECT_EQ(paired.residual, single.residual);
    EXPECT_EQ(std::memcmp(p1.data(), p2.data(), p1.size() * sizeof(double)), 0) << dims[0];
    EXPECT_LT(relativeResidual(pr, p2), 1e-8);
  }
}

TEST(PressureCg, CellsThatAreNoUnknownsKeepZeroPressure) {
  const Problem pr = irregularProblem(9, 8, 6, 3u);
  PcgOutcome outcome;
  const auto p = solve(pr, 2, outcome);
  for (std::size_t c = 0; c < p.size(); ++c) {
    if (pr.system.diag[c] == 0.0) {
      EXPECT_EQ(p[c], 0.0) << c;
    }
  }
}

TEST(PressureMultigrid, SolvesATankInSeveralTimesFewerIterationsThanMic0) {
  // Large enough for four levels (the coarsest exact), odd sizes so aggregates are cut at the
  // walls.
  for (const auto& dims : {std::array<int, 3>{33, 40, 21}, std::array<int, 3>{24, 37, 30}}) {
    const Problem pr = tankProblem(dims[0], dims[1], dims[2], 5u + dims[0]);
    PcgOutcome mic0, multigrid;
    solve(pr, 0, mic0);
    const auto p = solve(pr, 0, multigrid, FluidPreconditioner::kMultigrid);
    ASSERT_TRUE(multigrid.converged) << dims[0] << ": residual " << multigrid.residual;
    EXPECT_LT(relativeResidual(pr, p), 1e-8);
    std::printf("%dx%dx%d: MIC(0) %d, multigrid %d iterations\n", dims[0], dims[1], dims[2],
                mic0.iterations, multigrid.iterations);
    EXPECT_LE(3 * multigrid.iterations, mic0.iterations) << dims[0];
  }
}

TEST(PressureMultigrid, CellsThatAreNoUnknownsKeepZeroPressure) {
  const Problem pr = irregularProblem(19, 16, 12, 3u);
  PcgOutcome outcome;
  const auto p = solve(pr, 0, outcome, FluidPreconditioner::kMultigrid);
  ASSERT_TRUE(outcome.converged);
  for (std::size_t c = 0; c < p.size(); ++c) {
    if (pr.system.diag[c] == 0.0) {
      EXPECT_EQ(p[c], 0.0) << c;
    }
  }
}

TEST(PressureMultigrid, AnyThreadCountGivesTheSameBits) {
  // 34 x 30 x 22 cells: the fine level is above the size at which the cycle's passes use threads.
  const Problem pr = irregularProblem(34, 30, 22, 9u);
  PcgOutcome one;
  const auto p1 = solve(pr, 0, one, FluidPreconditioner::kMultigrid);
  ASSERT_TRUE(one.converged);
  for (int threads : {2, 3, 8}) {
    const Workers workers(threads);
    PcgOutcome many;
    const auto p = solve(pr, 0, many, FluidPreconditioner::kMultigrid, &workers);
    EXPECT_EQ(many.iterations, one.iterations) << threads;
    EXPECT_EQ(many.residual, one.residual) << threads;
    EXPECT_EQ(std::memcmp(p.data(), p1.data(), p.size() * sizeof(double)), 0) << threads;
  }
}

// The CG needs M^-1 symmetric and positive definite: u.(M^-1 v) = v.(M^-1 u) to round-off and
// u.(M^-1 u) > 0, here on random vectors over the unknowns, on a whole grid and on a slab (a
// block's part, the couplings across its faces dropped).
TEST(PressureMultigrid, TheCycleIsSymmetricAndPositiveDefinite) {
  const Problem pr = irregularProblem(27, 22, 18, 4u);
  const Grid& g = pr.grid;
  const std::size_t n = g.cells();
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Workers workers(1);
  for (const auto& slab : {std::array<int, 2>{0, 18}, std::array<int, 2>{5, 13}}) {
    Multigrid mg;
    mg.build(g, pr.system, slab[0], slab[1], workers);
    EXPECT_GE(mg.levels(), 3);
    for (int trial = 0; trial < 5; ++trial) {
      std::vector<double> u(n, 0.0), v(n, 0.0), mu(n, 0.0), mv(n, 0.0);
      for (std::size_t c = g.cell(0, 0, slab[0]); c < g.cell(0, 0, slab[1]); ++c) {
        if (pr.system.diag[c] == 0.0) continue;
        u[c] = unit(rng);
        v[c] = unit(rng);
      }
      mg.apply(u.data(), mu.data(), workers);
      mg.apply(v.data(), mv.data(), workers);
      double uMv = 0.0, vMu = 0.0, uMu = 0.0, scale = 0.0;
      for (std::size_t c = 0; c < n; ++c) {
        uMv += u[c] * mv[c];
        vMu += v[c] * mu[c];
        uMu += u[c] * mu[c];
        scale += std::abs(u[c] * mv[c]);
      }
      EXPECT_NEAR(uMv, vMu, 1e-12 * scale) << slab[0] << " trial " << trial;
      EXPECT_GT(uMu, 0.0) << slab[0] << " trial " << trial;
    }
  }
}

}  // namespace
}  // namespace vrflow::fluid::detail
