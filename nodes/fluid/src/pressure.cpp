#include "pressure.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace vrflow::fluid::detail {
namespace {

constexpr double kTau = 0.97;    // modified incomplete Cholesky blend (Bridson; 0.99: no better)
constexpr double kSigma = 0.25;  // safety: fall back to the diagonal when the pivot collapses
// Share of the couplings to neighbouring blocks moved to the diagonal (measured: 0.6 needs the
// fewest iterations on the benchmark's dam breaks, 49 instead of 56 with 2 blocks on
// 64 x 128 x 64, 28 instead of 36 on 32 x 64 x 32; 0.97 as inside a block needs more).
constexpr double kBlockTau = 0.6;

using Row = PcgWorkspace::Row;

struct Slab {
  int k0 = 0, k1 = 0;
  std::size_t c0 = 0, c1 = 0;
};

// The rows of the slab holding unknowns (cells with a diagonal), with their first and last
// unknown: every loop below runs over these only (air above a tank's surface is skipped).
void findRows(const Grid& g, const PressureSystem& A, const Slab& slab, std::vector<Row>& rows) {
  rows.clear();
  for (int k = slab.k0; k < slab.k1; ++k) {
    for (int j = 0; j < g.ny; ++j) {
      const std::size_t c = g.cell(0, j, k);
      int i0 = -1, i1 = -1;
      for (int i = 0; i < g.nx; ++i) {
        if (A.diag[c + static_cast<std::size_t>(i)] == 0.0) continue;
        if (i0 < 0) i0 = i;
        i1 = i;
      }
      if (i0 >= 0) rows.push_back({c + static_cast<std::size_t>(i0), j, k, i0, i1});
    }
  }
}

double sumOver(BlockComm* comm, double local) {
  return comm ? comm->sum(local) : local;
}

// q = A s on the unknowns, returning the local part of s.q; s must hold valid halo planes
// k0 - 1 and k1.
VRFLOW_FLUID_HOT
double multiply(const Grid& g, const PressureSystem& A, const double* s, double* q,
                const std::vector<Row>& rows) {
  const std::size_t sy = static_cast<std::size_t>(g.nx), sz = sy * static_cast<std::size_t>(g.ny);
  const double* diag = A.diag.data();
  const double* ax = A.ax.data();
  const double* ay = A.ay.data();
  const double* az = A.az.data();
  double sq = 0.0;
  for (const Row& row : rows) {
    const bool jLo = row.j > 0, jHi = row.j + 1 < g.ny, kLo = row.k > 0, kHi = row.k + 1 < g.nz;
    std::size_t c = row.c;
    for (int i = row.i0; i <= row.i1; ++i, ++c) {
      if (diag[c] == 0.0) {
        q[c] = 0.0;
        continue;
      }
      double v = diag[c] * s[c];
      if (i + 1 < g.nx) v += ax[c] * s[c + 1];
      if (i > 0) v += ax[c - 1] * s[c - 1];
      if (jHi) v += ay[c] * s[c + sy];
      if (jLo) v += ay[c - sy] * s[c - sy];
      if (kHi) v += az[c] * s[c + sz];
      if (kLo) v += az[c - sz] * s[c - sz];
      q[c] = v;
      sq += s[c] * v;
    }
  }
  return sq;
}

// MIC(0) of the slab's own block of A (couplings that leave the slab are dropped), stored as
// the pivots pc and the off-diagonals times their row's pivot.
VRFLOW_FLUID_HOT
void buildPreconditioner(const Grid& g, const PressureSystem& A, const Slab& slab,
                         PcgWorkspace& w) {
  const std::size_t sy = static_cast<std::size_t>(g.nx), sz = sy * static_cast<std::size_t>(g.ny);
  double* pc = w.pc.data();
  for (const Row& row : w.rows) {
    const bool kIn = row.k + 1 < slab.k1;  // the z coupling stays inside the slab
    std::size_t c = row.c;
    for (int i = row.i0; i <= row.i1; ++i, ++c) {
      if (A.diag[c] == 0.0) continue;
      double e = A.diag[c];
      // Couplings to the neighbouring blocks are dropped; as MIC(0) does with dropped fill-in,
      // part of them goes to the diagonal, so the factor nearly keeps A's row sums.
      if (row.k + 1 == slab.k1 && slab.k1 < g.nz) e += kBlockTau * A.az[c];
      if (row.k == slab.k0 && slab.k0 > 0) e += kBlockTau * A.az[c - sz];
      if (i > 0) {
        const std::size_t n = c - 1;
        const double a = A.ax[n] * pc[n];
        const double azn = kIn ? A.az[n] : 0.0;
        e -= a * a + kTau * A.ax[n] * (A.ay[n] + azn) * pc[n] * pc[n];
      }
      if (row.j > 0) {
        const std::size_t n = c - sy;
        const double a = A.ay[n] * pc[n];
        const double azn = kIn ? A.az[n] : 0.0;
        e -= a * a + kTau * A.ay[n] * (A.ax[n] + azn) * pc[n] * pc[n];
      }
      if (row.k > slab.k0) {
        const std::size_t n = c - sz;
        const double a = A.az[n] * pc[n];
        e -= a * a + kTau * A.az[n] * (A.ax[n] + A.ay[n]) * pc[n] * pc[n];
      }
      if (e < kSigma * A.diag[c]) e = A.diag[c];
      pc[c] = 1.0 / std::sqrt(e);
      w.axpc[c] = A.ax[c] * pc[c];
      w.aypc[c] = A.ay[c] * pc[c];
      w.azpc[c] = kIn ? A.az[c] * pc[c] : 0.0;
    }
  }
}

// The forward sweep of the preconditioner (L t = r) on one row, after an optional CG update of
// p and r on the same cells (fused: r is read once); returns the row's part of |r|^2.
template <bool kUpdate>
VRFLOW_FLUID_HOT double forwardRow(const Grid& g, const PcgWorkspace& w, const Row& row,
                                   double alpha, const double* s, const double* q, double* p,
                                   double* r, double* t) {
  const std::size_t sy = static_cast<std::size_t>(g.nx), sz = sy * static_cast<std::size_t>(g.ny);
  const double* pc = w.pc.data();
  const double* axpc = w.axpc.data();
  const double* aypc = w.aypc.data();
  const double* azpc = w.azpc.data();
  double rr = 0.0;
  std::size_t c = row.c;
  for (int i = row.i0; i <= row.i1; ++i, ++c) {
    if constexpr (kUpdate) {
      p[c] += alpha * s[c];
      r[c] -= alpha * q[c];
      rr += r[c] * r[c];
    }
    if (pc[c] == 0.0) {
      t[c] = 0.0;
      continue;
    }
    // Rows with no row below or behind them read zeros there (t is zero off the unknowns, and
    // the couplings of cells outside the slab are zero). The x neighbour, computed just before,
    // comes last, and the recurrence along x is one multiply and one subtraction: the pivot is
    // applied to the rest and to the coupling before. (Sweeping two rows j, j + 1 together to
    // keep two recurrences in flight measured no faster.)
    double v = r[c];
    if (row.j > 0) v -= aypc[c - sy] * t[c - sy];
    if (c >= sz) v -= azpc[c - sz] * t[c - sz];
    v *= pc[c];
    if (i > 0) v -= (pc[c] * axpc[c - 1]) * t[c - 1];
    t[c] = v;
  }
  return rr;
}

// The backward sweep (L^T z = t), completing z = M^-1 r; returns the local part of r.z.
VRFLOW_FLUID_HOT
double backward(const Grid& g, const PcgWorkspace& w, const double* r, const double* t, double* z) {
  const std::size_t sy = static_cast<std::size_t>(g.nx), sz = sy * static_cast<std::size_t>(g.ny);
  const double* pc = w.pc.data();
  const double* axpc = w.axpc.data();
  const double* aypc = w.aypc.data();
  const double* azpc = w.azpc.data();
  double rz = 0.0;
  for (auto it = w.rows.rbegin(); it != w.rows.rend(); ++it) {
    const Row& row = *it;
    const bool jHi = row.j + 1 < g.ny;
    std::size_t c = row.c + static_cast<std::size_t>(row.i1 - row.i0);
    for (int i = row.i1; i >= row.i0; --i, --c) {
      if (pc[c] == 0.0) {
        z[c] = 0.0;
        continue;
      }
      double v = t[c];
      if (jHi) v -= aypc[c] * z[c + sy];
      v -= azpc[c] * z[c + sz];
      v *= pc[c];
      if (i + 1 < g.nx) v -= (pc[c] * axpc[c]) * z[c + 1];
      z[c] = v;
      rz += r[c] * z[c];
    }
  }
  return rz;
}

template <typename F>
void forCells(const std::vector<Row>& rows, F&& f) {
  for (const Row& row : rows) {
    for (std::size_t c = row.c; c <= row.c + static_cast<std::size_t>(row.i1 - row.i0); ++c) f(c);
  }
}

// The same preconditioned CG rearranged after Chronopoulos and Gear (1989) for several blocks
// (not pipelined in the sense of overlapping, only merged reductions):
// A z is computed right after z = M^-1 r, and A s is updated from it (as = A z + beta as), so
// that r.z, z.Az and |r|^2 are summed over the blocks in one reduction per iteration (with the
// halo exchange of z, two synchronisations per iteration instead of three). In exact arithmetic
// the iterates are those of the plain CG. r holds b on entry, p zero.
void mergedReductions(const Grid& g, const PressureSystem& A, const Slab& slab, BlockComm* comm,
                      PcgWorkspace& w, double* p, double bNorm, double tol, int maxIterations,
                      std::uint64_t bytesPerCell, std::uint64_t activeCells, PcgOutcome& out) {
  const int planeSize = g.nx * g.ny;
  double* r = w.r.data();
  double* z = w.z.data();
  double* s = w.s.data();
  double* q = w.q.data();
  double* as = w.as.data();
  double* t = w.t.data();
  std::vector<double> sums(3);
  for (const Row& row : w.rows) forwardRow<false>(g, w, row, 0.0, s, q, p, r, t);
  sums[0] = backward(g, w, r, t, z);
  comm->exchangeHalo(w.z, planeSize, g.nz, slab.k0, slab.k1, 1);
  sums[1] = multiply(g, A, z, q, w.rows);
  sums[2] = 0.0;
  comm->sum(sums);
  double gamma = sums[0], delta = sums[1];
  if (delta <= 0.0) return;
  double alpha = gamma / delta;
  forCells(w.rows, [&](std::size_t c) {
    s[c] = z[c];
    as[c] = q[c];
  });
  double rNorm = bNorm;
  for (int it = 1; it <= maxIterations; ++it) {
    double rr = 0.0;
    for (const Row& row : w.rows) rr += forwardRow<true>(g, w, row, alpha, s, as, p, r, t);
    sums[0] = rr;
    sums[1] = backward(g, w, r, t, z);
    comm->exchangeHalo(w.z, planeSize, g.nz, slab.k0, slab.k1, 1);
    sums[2] = multiply(g, A, z, q, w.rows);
    comm->sum(sums);
    rNorm = std::sqrt(sums[0]);
    out.iterations = it;
    out.bytesTouched += bytesPerCell * activeCells;
    if (rNorm <= tol * bNorm) break;
    const double gammaNew = sums[1];
    const double beta = gammaNew / gamma;
    const double denominator = sums[2] - beta * gammaNew / alpha;
    if (denominator <= 0.0) break;  // breakdown: no descent left (round-off at convergence)
    alpha = gammaNew / denominator;
    gamma = gammaNew;
    forCells(w.rows, [&](std::size_t c) {
      s[c] = z[c] + beta * s[c];
      as[c] = q[c] + beta * as[c];
    });
  }
  out.residual = rNorm / bNorm;
  out.converged = out.residual <= tol;
}

}  // namespace

PcgOutcome solvePressure(const Grid& g, const PressureSystem& A, const std::vector<double>& b,
                         std::vector<double>& p, double tol, int maxIterations, BlockComm* comm,
                         PcgWorkspace& w) {
  const std::size_t n = g.cells();
  const int planeSize = g.nx * g.ny;
  Slab slab;
  if (comm) {
    slabOf(g.nz, comm->rank(), comm->size(), slab.k0, slab.k1);
  } else {
    slab.k1 = g.nz;
  }
  slab.c0 = static_cast<std::size_t>(slab.k0) * static_cast<std::size_t>(planeSize);
  slab.c1 = static_cast<std::size_t>(slab.k1) * static_cast<std::size_t>(planeSize);
  // Bytes streamed per iteration and cell of the rows holding unknowns, if nothing stayed in
  // cache: product 48 (diag, 3 couplings, s, q), update of p and r fused with the forward sweep
  // 88 (p and r read and written, s, q, 3 scaled couplings, pivot, t), backward sweep with r.z
  // 56 (t, 3 scaled couplings, pivot, z, r), direction update 24 (z, s read and written).
  // (A single-precision factor halving the sweeps' coupling traffic measured no faster.)
  constexpr std::uint64_t kBytesPerCellIteration = 216;

  PcgOutcome out;
  // Vectors are zero off the unknowns (the sweeps and the product read neighbours there; the
  // product's halo planes are exchanged before each use). Only the cells the last solve wrote,
  // its rows, need clearing.
  const std::size_t ps = static_cast<std::size_t>(planeSize);
  std::vector<double>* vectors[] = {&w.r,  &w.z,  &w.s,    &w.q,    &w.t,
                                    &w.as, &w.pc, &w.axpc, &w.aypc, &w.azpc};
  if (w.r.size() != n + ps) {
    for (auto* v : vectors) v->assign(n + ps, 0.0);
    w.rows.clear();
  }
  for (const Row& row : w.rows) {
    const auto from = static_cast<std::ptrdiff_t>(row.c);
    const auto count = static_cast<std::ptrdiff_t>(row.i1 - row.i0 + 1);
    for (auto* v : vectors) std::fill_n(v->begin() + from, count, 0.0);
  }
  findRows(g, A, slab, w.rows);
  std::uint64_t activeCells = 0;
  for (const Row& row : w.rows) activeCells += static_cast<std::uint64_t>(row.i1 - row.i0 + 1);
  p.assign(n, 0.0);
  double* r = w.r.data();
  double* z = w.z.data();
  double* s = w.s.data();
  double* q = w.q.data();
  double* pp = p.data();
  double bb = 0.0;
  for (const Row& row : w.rows) {
    for (std::size_t c = row.c; c <= row.c + static_cast<std::size_t>(row.i1 - row.i0); ++c) {
      r[c] = b[c];
      bb += b[c] * b[c];
    }
  }
  const double bNorm = std::sqrt(sumOver(comm, bb));
  if (bNorm == 0.0) return out;
  buildPreconditioner(g, A, slab, w);
  if (comm && comm->size() > 1) {
    mergedReductions(g, A, slab, comm, w, pp, bNorm, tol, maxIterations,
                     kBytesPerCellIteration + 24, activeCells, out);
    return out;
  }
  for (const Row& row : w.rows) forwardRow<false>(g, w, row, 0.0, s, q, pp, r, w.t.data());
  double rho = sumOver(comm, backward(g, w, r, w.t.data(), z));
  for (const Row& row : w.rows) {
    for (std::size_t c = row.c; c <= row.c + static_cast<std::size_t>(row.i1 - row.i0); ++c) {
      s[c] = z[c];
    }
  }
  double rNorm = bNorm;
  std::vector<double> sums(2);
  for (int it = 1; it <= maxIterations; ++it) {
    if (comm) comm->exchangeHalo(w.s, planeSize, g.nz, slab.k0, slab.k1, 1);
    const double sq = sumOver(comm, multiply(g, A, s, q, w.rows));
    if (sq <= 0.0) break;  // breakdown: no descent left (round-off at convergence)
    const double alpha = rho / sq;
    // The preconditioner runs before the convergence test so that |r|^2 and r.z are summed
    // over the blocks together (one reduction instead of two; the last one is wasted).
    double rr = 0.0;
    for (const Row& row : w.rows) rr += forwardRow<true>(g, w, row, alpha, s, q, pp, r, w.t.data());
    const double rz = backward(g, w, r, w.t.data(), z);
    double rhoNew = rz;
    if (comm) {
      sums[0] = rr;
      sums[1] = rz;
      comm->sum(sums);
      rr = sums[0];
      rhoNew = sums[1];
    }
    rNorm = std::sqrt(rr);
    out.iterations = it;
    out.bytesTouched += kBytesPerCellIteration * activeCells;
    if (rNorm <= tol * bNorm) break;
    const double beta = rhoNew / rho;
    rho = rhoNew;
    for (const Row& row : w.rows) {
      for (std::size_t c = row.c; c <= row.c + static_cast<std::size_t>(row.i1 - row.i0); ++c) {
        s[c] = z[c] + beta * s[c];
      }
    }
  }
  out.residual = rNorm / bNorm;
  out.converged = out.residual <= tol;
  return out;
}

}  // namespace vrflow::fluid::detail
