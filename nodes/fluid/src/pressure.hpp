#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "grid.hpp"
#include "multigrid.hpp"
#include "vrflow/fluid/block_comm.hpp"
#include "vrflow/fluid/settings.hpp"

// The pressure Poisson system on the cell grid (7-point, symmetric positive definite on the
// unknown cells) and its MIC(0)-preconditioned conjugate gradient. With a BlockComm each block
// solves its slab of planes; the preconditioner is then MIC(0) of the block's own part of the
// matrix (block Jacobi across blocks, with 0.6 of the dropped couplings moved to the diagonal),
// so iteration counts and the last bits of the result depend on the number of blocks.
// The multigrid-preconditioned CG (pressure_multigrid.cpp, multigrid.hpp) is the other choice.

namespace vrflow::fluid::detail {

struct PressureSystem {
  std::vector<double> diag;  ///< per cell; 0 for cells that are not unknowns
  std::vector<double> ax;    ///< coupling of cell (i,j,k) with (i+1,j,k), <= 0
  std::vector<double> ay;    ///< with (i,j+1,k)
  std::vector<double> az;    ///< with (i,j,k+1)
};

/// Scratch vectors of the CG, kept between steps so a step allocates nothing.
struct PcgWorkspace {
  std::vector<double> r, z, s, q, t, pc;
  std::vector<double> as;                ///< A s, updated instead of computed (several blocks only)
  std::vector<double> axpc, aypc, azpc;  ///< off-diagonals times the pivot of their row
  /// Rows (j, k) of the slab holding unknowns: first cell index, first and last i.
  struct Row {
    std::size_t c;
    int j, k, i0, i1;
  };
  std::vector<Row> rows;
  /// Up to kWaveRows consecutive rows of one plane, swept together (indices into rows), each
  /// one cell behind the row before it (see findWaves).
  static constexpr int kWaveRows = 2;
  struct Wave {
    int count = 0;
    int rows[kWaveRows] = {};
  };
  std::vector<Wave> waves;
  /// Rows per wave: 0 chooses by the grid's size (pairs up to 2^17 cells, see pressure.cpp);
  /// every choice gives the same bits.
  int rowsPerWave = 0;
  /// The preconditioner; the multigrid one runs its passes on `workers` (one thread if null).
  FluidPreconditioner preconditioner = FluidPreconditioner::kMic0;
  const Workers* workers = nullptr;
  Multigrid multigrid;
  /// Multigrid CG: the first row of each plane of the slab in `rows`, and per-plane partial
  /// sums (added in plane order: the thread count changes no bit).
  std::vector<std::size_t> planeRows;
  std::vector<double> planeSums, planeSums2;
};

struct PcgOutcome {
  int iterations = 0;
  double residual = 0.0;
  bool converged = true;
  std::uint64_t bytesTouched = 0;
};

/// q = A s on the rows [first, last) (see pressure.cpp), returning their part of s.q.
double multiplyRows(const Grid& grid, const PressureSystem& system, const double* s, double* q,
                    const PcgWorkspace::Row* first, const PcgWorkspace::Row* last);

/// p += alpha s and r -= alpha q on one row; returns the row's |r|^2.
double updateRow(const PcgWorkspace::Row& row, double alpha, const double* s, const double* q,
                 double* p, double* r);

/// r.z on one row.
double dotRow(const PcgWorkspace::Row& row, const double* r, const double* z);

/// The multigrid-preconditioned CG behind solvePressure() (pressure_multigrid.cpp): `w.rows`
/// are found, r holds b on them, p is zero; returns its outcome.
PcgOutcome solveWithMultigrid(const Grid& grid, const PressureSystem& system, int k0, int k1,
                              double* p, double bNorm, double tol, int maxIterations,
                              BlockComm* comm, PcgWorkspace& work);

/// Solves A p = b to |r| <= tol |b| (2-norms over the whole grid). `p` starts at zero (the last
/// step's pressure as a first guess measured no better: the right-hand side is dominated by
/// what the particle transfer and volume control ask anew each step). With `comm`, only this
/// block's slab of `p` is computed; the caller gathers it.
PcgOutcome solvePressure(const Grid& grid, const PressureSystem& system,
                         const std::vector<double>& b, std::vector<double>& p, double tol,
                         int maxIterations, BlockComm* comm, PcgWorkspace& work);

}  // namespace vrflow::fluid::detail
