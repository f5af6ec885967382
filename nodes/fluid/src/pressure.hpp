#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "grid.hpp"
#include "vrflow/fluid/block_comm.hpp"

// The pressure Poisson system on the cell grid (7-point, symmetric positive definite on the
// unknown cells) and its MIC(0)-preconditioned conjugate gradient. With a BlockComm each block
// solves its slab of planes; the preconditioner is then MIC(0) of the block's own part of the
// matrix (block Jacobi across blocks, with 0.6 of the dropped couplings moved to the diagonal),
// so iteration counts and the last bits of the result depend on the number of blocks.

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
};

struct PcgOutcome {
  int iterations = 0;
  double residual = 0.0;
  bool converged = true;
  std::uint64_t bytesTouched = 0;
};

/// Solves A p = b to |r| <= tol |b| (2-norms over the whole grid). `p` starts at zero (the last
/// step's pressure as a first guess measured no better: the right-hand side is dominated by
/// what the particle transfer and volume control ask anew each step). With `comm`, only this
/// block's slab of `p` is computed; the caller gathers it.
PcgOutcome solvePressure(const Grid& grid, const PressureSystem& system,
                         const std::vector<double>& b, std::vector<double>& p, double tol,
                         int maxIterations, BlockComm* comm, PcgWorkspace& work);

}  // namespace vrflow::fluid::detail
