#include "pressure.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

// The pressure CG on its own: a variable-coefficient Poisson system on an irregular set of
// unknowns (air pockets, rows with gaps, rows and planes with none), as the projection builds
// it. The preconditioner's sweeps can run rows one at a time or in pairs, the second row a cell
// behind the first; both must give the same bits, and the answer must solve the system.
namespace vrflow::fluid::detail {
namespace {

struct Problem {
  Grid grid;
  PressureSystem system;
  std::vector<double> b;
};

Problem irregularProblem(int nx, int ny, int nz, unsigned seed) {
  Problem pr;
  pr.grid.nx = nx;
  pr.grid.ny = ny;
  pr.grid.nz = nz;
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
  for (auto* v : {&A.diag, &A.ax, &A.ay, &A.az}) v->assign(n, 0.0);
  pr.b.assign(n, 0.0);
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

std::vector<double> solve(const Problem& pr, int rowsPerWave, PcgOutcome& outcome) {
  PcgWorkspace work;
  work.rowsPerWave = rowsPerWave;
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

}  // namespace
}  // namespace vrflow::fluid::detail
