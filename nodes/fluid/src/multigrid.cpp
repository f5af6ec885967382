#include "multigrid.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cstddef>

#include "parallel.hpp"
#include "pressure.hpp"

namespace vrflow::fluid::detail {
namespace {

// Chosen by the CG iterations per solve on the benchmark's coupled case (32 x 64 x 32, 20 boxes
// in the liquid, 23 steps; MIC(0) needs 24.6): V-cycles with two sweeps 10.8, W-cycles 8.0 (one
// sweep 11.7, three 7.0 but more time); Jacobi weight 2/3 12.6, 0.8 10.8, 0.9 10.2 with more
// time to the step (V-cycles); coarse scale 1.0 15.3, 1.6 10.8, 2.0 10.5 (V-cycles).
constexpr double kJacobiWeight = 0.8;  // damped Jacobi
constexpr int kSweeps = 2;             // before and after the coarse correction
constexpr int kCycles = 2;             // visits of the next level per cycle: a W-cycle
constexpr double kCoarseScale = 1.6;   // piecewise-constant interpolation's missing factor
constexpr std::size_t kCoarsestCells = 256;
// Levels smaller than this run on one thread: a pass over them is shorter than handing half of it
// to a worker. (16384 until 2026-11-27; 2048 took the benchmark's coupled 32 x 64 x 32 case's CG
// on 2 threads from 4.9-7.1 to 4.4-5.3 ms a step, alternated on the 2-core VM.)
constexpr std::size_t kThreadedCells = 2048;

// Calls f(k) for every plane of a level, on the solver's threads when the level is large.
template <typename F>
void forPlanes(const MultigridLevel& L, const Workers& workers, F&& f) {
  const int parts = L.sz * static_cast<std::size_t>(L.nz) >= kThreadedCells ? workers.threads() : 1;
  workers.forRanges(parts, static_cast<std::size_t>(L.nz),
                    [&](std::size_t, std::size_t begin, std::size_t end) {
                      for (std::size_t k = begin; k < end; ++k) f(static_cast<int>(k));
                    });
}

// Calls f(first, last) for the cells [first, last] of each row of plane k holding unknowns.
template <typename F>
void forRowsOfPlane(const MultigridLevel& L, int k, F&& f) {
  for (int j = 0; j < L.ny; ++j) {
    const std::size_t row =
        static_cast<std::size_t>(k) * static_cast<std::size_t>(L.ny) + static_cast<std::size_t>(j);
    if (L.rowFirst[row] > L.rowLast[row]) continue;
    f(L.cell(L.rowFirst[row], j, k), L.cell(L.rowLast[row], j, k));
  }
}

// On the cells [c, last] of a row (no bounds tests: see MultigridLevel): out = b - A x, or with
// kSweep a Jacobi sweep, out = x + weight / diag (b - A x).
template <bool kSweep>
VRFLOW_FLUID_HOT void stencilRow(const MultigridLevel& L, const double* __restrict x, std::size_t c,
                                 std::size_t last, double* __restrict out) {
  const double* __restrict d = L.diag.data();
  const double* __restrict ax = L.ax.data();
  const double* __restrict ay = L.ay.data();
  const double* __restrict az = L.az.data();
  const double* __restrict b = L.b.data();
  const double* __restrict w = L.weightedInverse.data();
  const std::size_t sy = L.sy, sz = L.sz;
  for (; c <= last; ++c) {
    const double ax0 = d[c] * x[c] + ax[c] * x[c + 1] + ax[c - 1] * x[c - 1];
    const double ay0 = ay[c] * x[c + sy] + ay[c - sy] * x[c - sy];
    const double az0 = az[c] * x[c + sz] + az[c - sz] * x[c - sz];
    const double r = b[c] - (ax0 + ay0 + az0);
    if constexpr (kSweep) {
      out[c] = x[c] + w[c] * r;
    } else {
      out[c] = r;
    }
  }
}

// x = weight / diag * b on a row: the first Jacobi sweep, from x = 0.
VRFLOW_FLUID_HOT void firstSweepRow(MultigridLevel& L, std::size_t c, std::size_t last) {
  const double* __restrict w = L.weightedInverse.data();
  const double* __restrict b = L.b.data();
  double* __restrict x = L.x.data();
  for (; c <= last; ++c) x[c] = w[c] * b[c];
}

// x += scale * (coarse x of the cell's aggregate) on the unknowns of fine row (j, k).
VRFLOW_FLUID_HOT void prolongRow(MultigridLevel& fine, const MultigridLevel& coarse, int j, int k,
                                 int first, int last) {
  double* __restrict x = fine.x.data();
  const double* __restrict d = fine.diag.data();
  const double* __restrict cx = coarse.x.data() + coarse.cell(0, j / 2, k / 2);
  const std::size_t c0 = fine.cell(0, j, k);
  for (int i = first; i <= last; ++i) {
    const std::size_t c = c0 + static_cast<std::size_t>(i);
    x[c] += d[c] > 0.0 ? kCoarseScale * cx[i / 2] : 0.0;
  }
}

// Sizes a level, or when it keeps its size clears the vectors on the last solve's rows only
// (everything off a level's rows stays zero: its passes write its rows only).
void sizeLevel(MultigridLevel& L, int nx, int ny, int nz) {
  const std::size_t rows = static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz);
  if (L.nx == nx && L.ny == ny && L.nz == nz) {
    for (std::size_t row = 0; row < rows; ++row) {
      if (L.rowFirst[row] > L.rowLast[row]) continue;
      const std::size_t first = L.pad + row * L.sy + static_cast<std::size_t>(L.rowFirst[row]);
      const auto count = static_cast<std::size_t>(L.rowLast[row] - L.rowFirst[row] + 1);
      for (auto* v : {&L.x, &L.b, &L.r}) {
        std::fill_n(v->begin() + static_cast<std::ptrdiff_t>(first), count, 0.0);
      }
    }
  } else {
    L.nx = nx;
    L.ny = ny;
    L.nz = nz;
    L.sy = static_cast<std::size_t>(nx);
    L.sz = L.sy * static_cast<std::size_t>(ny);
    L.pad = L.sz + 1;
    const std::size_t size = L.pad + L.sz * static_cast<std::size_t>(nz) + L.sz + 1;
    for (auto* v : {&L.diag, &L.ax, &L.ay, &L.az, &L.weightedInverse, &L.x, &L.b, &L.r}) {
      v->assign(size, 0.0);
    }
  }
  L.rowFirst.assign(rows, nx);
  L.rowLast.assign(rows, -1);
}

// After a level's matrix is filled on plane k: its rows' extents and Jacobi weights.
void finishPlane(MultigridLevel& L, int k) {
  for (int j = 0; j < L.ny; ++j) {
    const std::size_t row =
        static_cast<std::size_t>(k) * static_cast<std::size_t>(L.ny) + static_cast<std::size_t>(j);
    for (int i = 0; i < L.nx; ++i) {
      const std::size_t c = L.cell(i, j, k);
      L.weightedInverse[c] = 0.0;
      if (L.diag[c] <= 0.0) continue;
      L.rowFirst[row] = std::min(L.rowFirst[row], i);
      L.rowLast[row] = i;
      L.weightedInverse[c] = kJacobiWeight / L.diag[c];
    }
  }
}

// The fine level: planes [k0, k1) of A, couplings across the slab's faces dropped.
void copyFine(const Grid& g, const PressureSystem& A, int k0, MultigridLevel& L, int k) {
  const std::size_t from = g.cell(0, 0, k0 + k);
  const std::size_t to = L.cell(0, 0, k);
  std::copy_n(A.diag.begin() + static_cast<std::ptrdiff_t>(from), L.sz,
              L.diag.begin() + static_cast<std::ptrdiff_t>(to));
  std::copy_n(A.ax.begin() + static_cast<std::ptrdiff_t>(from), L.sz,
              L.ax.begin() + static_cast<std::ptrdiff_t>(to));
  std::copy_n(A.ay.begin() + static_cast<std::ptrdiff_t>(from), L.sz,
              L.ay.begin() + static_cast<std::ptrdiff_t>(to));
  if (k + 1 < L.nz) {
    std::copy_n(A.az.begin() + static_cast<std::ptrdiff_t>(from), L.sz,
                L.az.begin() + static_cast<std::ptrdiff_t>(to));
  } else {
    std::fill_n(L.az.begin() + static_cast<std::ptrdiff_t>(to), L.sz, 0.0);
  }
  finishPlane(L, k);
}

// Coarse plane K of P^T A P (see multigrid.hpp) from fine planes 2K and 2K + 1.
void coarsenPlane(const MultigridLevel& f, MultigridLevel& c, int K) {
  for (auto* v : {&c.diag, &c.ax, &c.ay, &c.az}) {
    std::fill_n(v->begin() + static_cast<std::ptrdiff_t>(c.cell(0, 0, K)), c.sz, 0.0);
  }
  for (int k = 2 * K; k < std::min(2 * K + 2, f.nz); ++k) {
    for (int j = 0; j < f.ny; ++j) {
      const std::size_t row = static_cast<std::size_t>(k) * static_cast<std::size_t>(f.ny) +
                              static_cast<std::size_t>(j);
      for (int i = f.rowFirst[row]; i <= f.rowLast[row]; ++i) {
        const std::size_t fc = f.cell(i, j, k);
        if (f.diag[fc] <= 0.0) continue;
        const std::size_t cc = c.cell(i / 2, j / 2, K);
        c.diag[cc] += f.diag[fc];
        // A coupling inside the aggregate appears twice in P^T A P's diagonal.
        if (i % 2 == 0) {
          c.diag[cc] += 2.0 * f.ax[fc];
        } else {
          c.ax[cc] += f.ax[fc];
        }
        if (j % 2 == 0) {
          c.diag[cc] += 2.0 * f.ay[fc];
        } else {
          c.ay[cc] += f.ay[fc];
        }
        if (k % 2 == 0) {
          c.diag[cc] += 2.0 * f.az[fc];
        } else {
          c.az[cc] += f.az[fc];
        }
      }
    }
  }
  finishPlane(c, K);
}

// Coarse b on plane K = the sum of the fine residuals b - A x of its aggregates (the residual
// is computed here, row by row, into f.r).
void restrictPlane(MultigridLevel& f, MultigridLevel& c, int K) {
  forRowsOfPlane(c, K, [&](std::size_t first, std::size_t last) {
    std::fill(c.b.begin() + static_cast<std::ptrdiff_t>(first),
              c.b.begin() + static_cast<std::ptrdiff_t>(last) + 1, 0.0);
  });
  for (int k = 2 * K; k < std::min(2 * K + 2, f.nz); ++k) {
    for (int j = 0; j < f.ny; ++j) {
      const std::size_t row = static_cast<std::size_t>(k) * static_cast<std::size_t>(f.ny) +
                              static_cast<std::size_t>(j);
      if (f.rowFirst[row] > f.rowLast[row]) continue;
      stencilRow<false>(f, f.x.data(), f.cell(f.rowFirst[row], j, k), f.cell(f.rowLast[row], j, k),
                        f.r.data());
      double* cb = c.b.data() + c.cell(0, j / 2, K);
      const double* fr = f.r.data() + f.cell(0, j, k);
      for (int i = f.rowFirst[row]; i <= f.rowLast[row]; ++i) cb[i / 2] += fr[i];
    }
  }
}

}  // namespace

struct Multigrid::Coarsest {
  std::vector<std::size_t> unknowns;  ///< the level's unknown cells, in order
  Eigen::MatrixXd matrix;
  Eigen::LLT<Eigen::MatrixXd> factor;
  Eigen::VectorXd vector;
  bool factored = false;
};

Multigrid::Multigrid() : coarsest_(std::make_unique<Coarsest>()) {}
Multigrid::~Multigrid() = default;
Multigrid::Multigrid(Multigrid&&) noexcept = default;
Multigrid& Multigrid::operator=(Multigrid&&) noexcept = default;

void Multigrid::build(const Grid& g, const PressureSystem& A, int k0, int k1,
                      const Workers& workers) {
  sliceBegin_ = g.cell(0, 0, k0);
  sliceCells_ = g.cell(0, 0, k1) - sliceBegin_;
  int nx = g.nx, ny = g.ny, nz = k1 - k0;
  std::size_t count = 0;
  for (;;) {
    if (levels_.size() <= count) levels_.emplace_back();
    sizeLevel(levels_[count], nx, ny, nz);
    ++count;
    const std::size_t cells =
        static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz);
    if (cells <= kCoarsestCells || (nx == 1 && ny == 1 && nz == 1)) break;
    nx = (nx + 1) / 2;
    ny = (ny + 1) / 2;
    nz = (nz + 1) / 2;
  }
  levels_.resize(count);
  forPlanes(levels_[0], workers, [&](int k) { copyFine(g, A, k0, levels_[0], k); });
  for (std::size_t l = 1; l < levels_.size(); ++l) {
    forPlanes(levels_[l], workers, [&](int K) { coarsenPlane(levels_[l - 1], levels_[l], K); });
  }

  // The coarsest level's dense matrix on its unknowns, factored once per solve.
  const MultigridLevel& L = levels_.back();
  Coarsest& co = *coarsest_;
  co.unknowns.clear();
  std::vector<int> index(L.diag.size(), -1);
  for (int k = 0; k < L.nz; ++k) {
    for (int j = 0; j < L.ny; ++j) {
      for (int i = 0; i < L.nx; ++i) {
        const std::size_t c = L.cell(i, j, k);
        if (L.diag[c] <= 0.0) continue;
        index[c] = static_cast<int>(co.unknowns.size());
        co.unknowns.push_back(c);
      }
    }
  }
  const auto size = static_cast<Eigen::Index>(co.unknowns.size());
  co.matrix.setZero(size, size);
  co.vector.resize(size);
  for (Eigen::Index u = 0; u < size; ++u) {
    const std::size_t c = co.unknowns[static_cast<std::size_t>(u)];
    co.matrix(u, u) = L.diag[c];
    const std::size_t neighbours[3] = {c + 1, c + L.sy, c + L.sz};
    const double couplings[3] = {L.ax[c], L.ay[c], L.az[c]};
    for (int a = 0; a < 3; ++a) {
      if (couplings[a] == 0.0 || index[neighbours[a]] < 0) continue;
      co.matrix(u, index[neighbours[a]]) = couplings[a];
      co.matrix(index[neighbours[a]], u) = couplings[a];
    }
  }
  co.factor.compute(co.matrix);
  // A coarse matrix that is not definite (liquid sealed off from air: pressure known up to a
  // constant) falls back to Jacobi on that level, which keeps the cycle symmetric.
  co.factored = size > 0 && co.factor.info() == Eigen::Success;
}

void Multigrid::solveCoarsest() {
  MultigridLevel& L = levels_.back();
  Coarsest& co = *coarsest_;
  if (!co.factored) {
    forPlanes(L, Workers(1), [&](int k) {
      forRowsOfPlane(L, k, [&](std::size_t c, std::size_t last) { firstSweepRow(L, c, last); });
    });
    return;
  }
  for (std::size_t u = 0; u < co.unknowns.size(); ++u) {
    co.vector[static_cast<Eigen::Index>(u)] = L.b[co.unknowns[u]];
  }
  co.factor.solveInPlace(co.vector);
  for (std::size_t u = 0; u < co.unknowns.size(); ++u) {
    L.x[co.unknowns[u]] = co.vector[static_cast<Eigen::Index>(u)];
  }
}

void Multigrid::cycle(std::size_t l, const Workers& workers, bool fromZero) {
  if (l + 1 == levels_.size()) {
    solveCoarsest();
    return;
  }
  MultigridLevel& L = levels_[l];
  // A Jacobi sweep writes the new x into r, which then trades places with x.
  const auto sweep = [&] {
    forPlanes(L, workers, [&](int k) {
      forRowsOfPlane(L, k, [&](std::size_t c, std::size_t last) {
        stencilRow<true>(L, L.x.data(), c, last, L.r.data());
      });
    });
    L.x.swap(L.r);
  };
  if (fromZero) {
    forPlanes(L, workers, [&](int k) {
      forRowsOfPlane(L, k, [&](std::size_t c, std::size_t last) { firstSweepRow(L, c, last); });
    });
  } else {
    sweep();
  }
  for (int s = 1; s < kSweeps; ++s) sweep();
  MultigridLevel& C = levels_[l + 1];
  forPlanes(C, workers, [&](int K) { restrictPlane(L, C, K); });
  cycle(l + 1, workers, true);
  for (int g = 1; g < kCycles; ++g) cycle(l + 1, workers, false);
  forPlanes(L, workers, [&](int k) {
    for (int j = 0; j < L.ny; ++j) {
      const std::size_t row = static_cast<std::size_t>(k) * static_cast<std::size_t>(L.ny) +
                              static_cast<std::size_t>(j);
      if (L.rowFirst[row] <= L.rowLast[row]) {
        prolongRow(L, C, j, k, L.rowFirst[row], L.rowLast[row]);
      }
    }
  });
  for (int s = 0; s < kSweeps; ++s) sweep();
}

void Multigrid::apply(const double* r, double* z, const Workers& workers) {
  MultigridLevel& L = levels_[0];
  std::copy_n(r + sliceBegin_, sliceCells_, L.b.begin() + static_cast<std::ptrdiff_t>(L.pad));
  cycle(0, workers, true);
  std::copy_n(L.x.begin() + static_cast<std::ptrdiff_t>(L.pad), sliceCells_, z + sliceBegin_);
}

std::size_t Multigrid::fineActiveCells() const {
  if (levels_.empty()) return 0;
  std::size_t cells = 0;
  const MultigridLevel& L = levels_[0];
  for (std::size_t row = 0; row < L.rowFirst.size(); ++row) {
    if (L.rowFirst[row] <= L.rowLast[row]) {
      cells += static_cast<std::size_t>(L.rowLast[row] - L.rowFirst[row] + 1);
    }
  }
  return cells;
}

}  // namespace vrflow::fluid::detail
