#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "grid.hpp"

// The multigrid preconditioner of the pressure CG (after McAdams, Sifakis and Teran 2010, with
// the coarse levels built algebraically): one symmetric W-cycle approximates A^-1 r on a
// block's slab of planes.
//
// Levels: the coarse cell (I, J, K) aggregates the fine cells (2I..2I+1, 2J..2J+1, 2K..2K+1),
// and the coarse matrix is the Galerkin product P^T A P with P piecewise constant over the
// aggregates. That product of a 7-point matrix is again 7-point (a coarse coupling sums the four
// fine couplings across the aggregates' shared face, the couplings inside an aggregate fold into
// its diagonal), and it follows the free surface, the bodies' densities and the walls of any
// level without rediscretising them: a coarse cell is an unknown when one of its fine cells is.
// Piecewise-constant interpolation makes the coarse correction about half as large as it should
// be on a Poisson matrix (Braess 1995), so it is scaled by kCoarseScale.
//
// Smoothing: damped Jacobi (weight kJacobiWeight), the same number of sweeps before and after
// the coarse correction, so that the cycle is a symmetric positive definite operator and the CG
// stays valid. Each level visits the next twice (a W-cycle: 8 CG iterations where V-cycles need
// 11, for an eighth more work on the coarse levels); the second visit starts from the first's
// result, which keeps the cycle symmetric. Jacobi writes every cell from the previous sweep only:
// planes run on the solver's threads and give the same bits whatever their number. The coarsest
// level (at most kCoarsestCells cells) is solved exactly by Eigen's dense Cholesky factor.
//
// With several blocks each block's cycle works on its own slab only (couplings across the
// slab's faces are dropped): block Jacobi across blocks, as MIC(0) is.

namespace vrflow::fluid::detail {

struct PressureSystem;
class Workers;

/// One level's matrix and vectors on a box of cells, x fastest, with one zero plane before and
/// after the box (and one zero cell at either end) so the 7-point loops need no bounds tests.
struct MultigridLevel {
  int nx = 0, ny = 0, nz = 0;
  std::size_t sy = 0, sz = 0;  ///< strides of y and z
  std::size_t pad = 0;         ///< index of cell (0, 0, 0) in every array
  std::vector<double> diag, ax, ay, az;
  std::vector<double> weightedInverse;  ///< Jacobi weight / diagonal; 0 off the unknowns
  std::vector<double> x, b, r;          ///< solution, right-hand side, residual
  /// Per row (j, k): first and last i holding an unknown (first > last: none).
  std::vector<int> rowFirst, rowLast;
  std::size_t cell(int i, int j, int k) const {
    return pad + static_cast<std::size_t>(k) * sz + static_cast<std::size_t>(j) * sy +
           static_cast<std::size_t>(i);
  }
};

/// A multigrid hierarchy for one slab of a pressure system; rebuilt every solve (the liquid and
/// the bodies move), its storage kept.
class Multigrid {
 public:
  Multigrid();
  ~Multigrid();
  Multigrid(Multigrid&&) noexcept;
  Multigrid& operator=(Multigrid&&) noexcept;

  /// Builds the levels for planes [k0, k1) of `A` on `grid`.
  void build(const Grid& grid, const PressureSystem& A, int k0, int k1, const Workers& workers);

  /// z = M^-1 r (one W-cycle) on the slab's cells (vectors indexed like the grid); z is written on
  /// every cell of the slab (0 off the unknowns).
  void apply(const double* r, double* z, const Workers& workers);

  /// Number of levels, the exactly solved one included.
  int levels() const { return static_cast<int>(levels_.size()); }

  /// Cells of the fine level's rows with unknowns (what one fine sweep streams over).
  std::size_t fineActiveCells() const;

 private:
  void cycle(std::size_t level, const Workers& workers, bool fromZero);
  void solveCoarsest();

  std::vector<MultigridLevel> levels_;
  std::size_t sliceBegin_ = 0, sliceCells_ = 0;  ///< the slab in the grid's indexing
  struct Coarsest;  ///< the coarsest level's dense factor (Eigen, kept out of this header)
  std::unique_ptr<Coarsest> coarsest_;
};

}  // namespace vrflow::fluid::detail
