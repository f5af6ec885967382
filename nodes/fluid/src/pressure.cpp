#include "pressure.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <type_traits>

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

// The sum of a Quad's lanes, in a fixed order.
double lanes(const Quad& v) {
  return (v[0] + v[1]) + (v[2] + v[3]);
}

// p += alpha s and r -= alpha q on one row, four cells at a time; returns the row's |r|^2.
VRFLOW_FLUID_HOT double updateRowImpl(const Row& row, double alpha, const double* s,
                                      const double* q, double* p, double* r) {
  const std::size_t end = row.c + static_cast<std::size_t>(row.i1 - row.i0) + 1;
  const Quad a = {alpha, alpha, alpha, alpha};
  Quad rr4 = {0, 0, 0, 0};
  std::size_t c = row.c;
  for (; c + 4 <= end; c += 4) {
    Quad pv, sv, rv, qv;
    load(pv, p + c);
    load(sv, s + c);
    load(rv, r + c);
    load(qv, q + c);
    pv += a * sv;
    rv -= a * qv;
    store(p + c, pv);
    store(r + c, rv);
    rr4 += rv * rv;
  }
  double rr = 0.0;
  for (; c < end; ++c) {
    p[c] += alpha * s[c];
    r[c] -= alpha * q[c];
    rr += r[c] * r[c];
  }
  return rr + lanes(rr4);
}

// r.z on one row, four cells at a time.
VRFLOW_FLUID_HOT double dotRowImpl(const Row& row, const double* r, const double* z) {
  const std::size_t end = row.c + static_cast<std::size_t>(row.i1 - row.i0) + 1;
  Quad rz4 = {0, 0, 0, 0};
  std::size_t c = row.c;
  for (; c + 4 <= end; c += 4) {
    Quad rv, zv;
    load(rv, r + c);
    load(zv, z + c);
    rz4 += rv * zv;
  }
  double rz = 0.0;
  for (; c < end; ++c) rz += r[c] * z[c];
  return rz + lanes(rz4);
}

// q = A s on the unknowns, returning the local part of s.q; s must hold valid halo planes
// k0 - 1 and k1. Rows above the grid's first plane run four cells at a time with no bounds
// tests: couplings across the walls are zero and their neighbours lie inside the arrays (s has
// a plane beyond the grid), and cells that are not unknowns get q = 0. Partial sums of s.q are
// kept per lane, so the sum is not one chain of dependent additions.
VRFLOW_FLUID_HOT
double multiplyRange(const Grid& g, const PressureSystem& A, const double* s, double* q,
                     const Row* first, const Row* last) {
  const std::size_t sy = static_cast<std::size_t>(g.nx), sz = sy * static_cast<std::size_t>(g.ny);
  const double* diag = A.diag.data();
  const double* ax = A.ax.data();
  const double* ay = A.ay.data();
  const double* az = A.az.data();
  Quad sq4 = {0, 0, 0, 0};
  double sq = 0.0;
  for (const Row* it = first; it != last; ++it) {
    const Row& row = *it;
    const std::size_t end = row.c + static_cast<std::size_t>(row.i1 - row.i0) + 1;
    std::size_t c = row.c;
    int i = row.i0;
    if (row.k > 0) {
      for (; c + 4 <= end; c += 4, i += 4) {
        Quad d, sc, v;
        load(d, diag + c);
        load(sc, s + c);
        v = d * sc;
        // v += coupling * neighbour, four cells at a time.
        const auto add = [&v](const double* coupling, const double* neighbour) {
          Quad a, sn;
          load(a, coupling);
          load(sn, neighbour);
          v += a * sn;
        };
        add(ax + c, s + c + 1);
        add(ax + c - 1, s + c - 1);
        add(ay + c, s + c + sy);
        add(ay + c - sy, s + c - sy);
        add(az + c, s + c + sz);
        add(az + c - sz, s + c - sz);
        v = d == 0.0 ? Quad{0, 0, 0, 0} : v;
        store(q + c, v);
        sq4 += sc * v;
      }
    }
    const bool jLo = row.j > 0, jHi = row.j + 1 < g.ny, kLo = row.k > 0, kHi = row.k + 1 < g.nz;
    for (; c < end; ++i, ++c) {
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
  return sq + lanes(sq4);
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

// The sweeps of the preconditioner are recurrences: a cell needs the cells before it along x,
// y and z. Along x that is one chain of dependent multiply-adds per row, so a row at a time runs
// at the latency of that chain. The sweeps take consecutive rows of a plane in pairs (a wave)
// and run the second row one cell behind the first: cell (i, j) needs (i - 1, j), one step
// before in its own row, and (i, j - 1), one step before in the row below, so two chains are
// in flight. The rows of a wave lie next to each other in memory, so the sweep still streams
// through the vectors in order. Each cell sees the same operations in the same order as in a
// row-by-row sweep, so the result is the same to the bit, whichever way a grid is swept.
// Measured on a 2-core EPYC against a row at a time (CG time per step, alternating runs): on
// 32 x 64 x 32, two rows 3.9 against 5.4 ms (three or four rows gained less); on 64 x 128 x 64
// two rows lost 15-30 % (90-120 against 78-93 ms), on one rank as on two, with the vectors (4
// MiB each) out of the caches, where interleaving two rows seems to cost the prefetchers more
// than the second chain gains. So grids up to kPairedSweepCells cells (1 MiB per vector) sweep
// rows in pairs, larger ones a row at a time. (Rows of one anti-diagonal j + k across the slab,
// tried first, scattered a wave over every plane and lost 1.5x on the large grid.)
constexpr std::size_t kPairedSweepCells = std::size_t{1} << 17;

void findWaves(const std::vector<Row>& rows, int rowsPerWave, PcgWorkspace& w) {
  w.waves.clear();
  for (std::size_t r = 0; r < rows.size();) {
    PcgWorkspace::Wave wave;
    while (r < rows.size() && wave.count < rowsPerWave &&
           (wave.count == 0 || rows[r].k == rows[static_cast<std::size_t>(wave.rows[0])].k)) {
      wave.rows[wave.count++] = static_cast<int>(r++);
    }
    w.waves.push_back(wave);
  }
}

// The lanes of one wave: each row's cell at the wave's first i, and its tests. All lanes run
// over the same span of i (the union of the rows'), cells outside a row's own span being no
// unknowns. `below` (`above`) tells that the lane's row j - 1 (j + 1) is the lane before (after)
// it, whose value one step back the forward (backward) sweep still holds in a register.
template <int L>
struct Lanes {
  std::size_t c[L];
  bool jLo[L], jHi[L], kLo[L], below[L], above[L];
  int lo = 0, hi = 0;

  Lanes(const Grid& g, const std::vector<Row>& rows, const PcgWorkspace::Wave& wave) {
    const std::size_t sz = static_cast<std::size_t>(g.nx) * static_cast<std::size_t>(g.ny);
    lo = g.nx;
    hi = -1;
    for (int l = 0; l < L; ++l) {
      const Row& row = rows[static_cast<std::size_t>(wave.rows[l])];
      lo = std::min(lo, row.i0);
      hi = std::max(hi, row.i1);
    }
    for (int l = 0; l < L; ++l) {
      const Row& row = rows[static_cast<std::size_t>(wave.rows[l])];
      c[l] = row.c - static_cast<std::size_t>(row.i0) + static_cast<std::size_t>(lo);
      jLo[l] = row.j > 0;
      jHi[l] = row.j + 1 < g.ny;
      kLo[l] = c[l] >= sz;
      below[l] = l > 0 && rows[static_cast<std::size_t>(wave.rows[l - 1])].j + 1 == row.j;
      above[l] = l + 1 < L && rows[static_cast<std::size_t>(wave.rows[l + 1])].j == row.j + 1;
    }
  }
};

// The steps of a wave: lane m works on position k = step - m of the span, so each lane is one
// step behind the lane before it. The lanes run from the last, so that lane m still finds the
// value lane m - 1 computed in the step before. The first and last L - 1 steps have lanes
// outside the span; the steps between have none and run without tests.
template <int L, typename Cell>
[[gnu::always_inline]] inline void skewedSteps(int span, Cell&& cell) {
  const auto edge = [&](int step) __attribute__((always_inline)) {
    for (int m = L - 1; m >= 0; --m) {
      if (step - m >= 0 && step - m < span) cell(m, step - m);
    }
  };
  for (int step = 0; step < L - 1; ++step) edge(step);
  for (int step = L - 1; step < span; ++step) {
#pragma GCC unroll 4
    for (int m = L - 1; m >= 0; --m) cell(m, step - m);
  }
  for (int step = std::max(L - 1, span); step < span + L - 1; ++step) edge(step);
}

// What both sweeps read: the grid's y and z strides and the preconditioner's arrays.
struct SweepArrays {
  SweepArrays(const Grid& g, const PcgWorkspace& w)
      : sy(static_cast<std::size_t>(g.nx)),
        sz(sy * static_cast<std::size_t>(g.ny)),
        pc(w.pc.data()),
        axpc(w.axpc.data()),
        aypc(w.aypc.data()),
        azpc(w.azpc.data()) {}
  std::size_t sy, sz;
  const double* pc;
  const double* axpc;
  const double* aypc;
  const double* azpc;
};

// The forward sweep (L t = r) over the rows of one wave, lane l at cell i = lo + step - l.
// Cells of the span that are not unknowns (pivot 0) get t = 0, as they hold. The recurrence
// along x is one multiply-add: the pivot is applied to the rest and to the coupling before.
template <int L>
VRFLOW_FLUID_HOT void forwardWave(const Grid& g, const PcgWorkspace& w,
                                  const PcgWorkspace::Wave& wave, const double* r, double* t) {
  const auto [sy, sz, pc, axpc, aypc, azpc] = SweepArrays(g, w);
  const Lanes<L> lanes(g, w.rows, wave);
  double before[L] = {};
  const auto cell = [&](int l, int at) __attribute__((always_inline)) {
    const std::size_t c = lanes.c[l] + static_cast<std::size_t>(at);
    double v = 0.0;
    if (pc[c] != 0.0) {
      v = r[c];
      if (lanes.jLo[l])
        v -= aypc[c - sy] * (lanes.below[l] ? before[l > 0 ? l - 1 : 0] : t[c - sy]);
      if (lanes.kLo[l]) v -= azpc[c - sz] * t[c - sz];
      v *= pc[c];
      if (lanes.lo + at > 0) v -= (pc[c] * axpc[c - 1]) * before[l];
    }
    t[c] = v;
    before[l] = v;
  };
  skewedSteps<L>(lanes.hi - lanes.lo + 1, cell);
}

// The backward sweep (L^T z = t) over the rows of one wave, from the last cell; lane l at cell
// i = hi - step + (L - 1 - l), the lanes from the first (lane l reads lane l + 1's value of the
// step before).
template <int L>
VRFLOW_FLUID_HOT void backwardWave(const Grid& g, const PcgWorkspace& w,
                                   const PcgWorkspace::Wave& wave, const double* t, double* z) {
  const auto [sy, sz, pc, axpc, aypc, azpc] = SweepArrays(g, w);
  const Lanes<L> lanes(g, w.rows, wave);
  double after[L] = {};
  const auto cell = [&](int l, int at) __attribute__((always_inline)) {
    const std::size_t c = lanes.c[l] + static_cast<std::size_t>(at);
    double v = 0.0;
    if (pc[c] != 0.0) {
      v = t[c];
      if (lanes.jHi[l]) v -= aypc[c] * (lanes.above[l] ? after[l + 1 < L ? l + 1 : l] : z[c + sy]);
      v -= azpc[c] * z[c + sz];
      v *= pc[c];
      if (lanes.lo + at + 1 < g.nx) v -= (pc[c] * axpc[c]) * after[l];
    }
    z[c] = v;
    after[l] = v;
  };
  // Lane l trails lane l + 1 by a step: as lead lane L - 1 - l, from the span's end.
  const int span = lanes.hi - lanes.lo + 1;
  skewedSteps<L>(
      span, [&](int m, int k) __attribute__((always_inline)) { cell(L - 1 - m, span - 1 - k); });
}

// Calls f with the wave's number of lanes as a constant (one instance of a sweep per count).
template <int L = PcgWorkspace::kWaveRows, typename F>
void withLanes(int count, F&& f) {
  if constexpr (L == 1) {
    f(std::integral_constant<int, 1>{});
  } else if (count == L) {
    f(std::integral_constant<int, L>{});
  } else {
    withLanes<L - 1>(count, f);
  }
}

// The forward sweep over every wave, each row of a wave first updated (p += alpha s,
// r -= alpha q) when kUpdate (fused: r is fresh in cache for the sweep); returns |r|^2.
template <bool kUpdate>
double forward(const Grid& g, const PcgWorkspace& w, double alpha, const double* s, const double* q,
               double* p, double* r, double* t) {
  double rr = 0.0;
  for (const auto& wave : w.waves) {
    if constexpr (kUpdate) {
      for (int l = 0; l < wave.count; ++l) {
        rr += updateRowImpl(w.rows[static_cast<std::size_t>(wave.rows[l])], alpha, s, q, p, r);
      }
    }
    withLanes(wave.count, [&](auto lanes) { forwardWave<lanes()>(g, w, wave, r, t); });
  }
  return rr;
}

// The backward sweep over every wave, last first, completing z = M^-1 r; returns the local part
// of r.z.
double backward(const Grid& g, const PcgWorkspace& w, const double* r, const double* t, double* z) {
  double rz = 0.0;
  for (auto it = w.waves.rbegin(); it != w.waves.rend(); ++it) {
    withLanes(it->count, [&](auto lanes) { backwardWave<lanes()>(g, w, *it, t, z); });
    for (int l = it->count - 1; l >= 0; --l) {
      rz += dotRowImpl(w.rows[static_cast<std::size_t>(it->rows[l])], r, z);
    }
  }
  return rz;
}

double multiply(const Grid& g, const PressureSystem& A, const double* s, double* q,
                const std::vector<Row>& rows) {
  return multiplyRange(g, A, s, q, rows.data(), rows.data() + rows.size());
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
  forward<false>(g, w, 0.0, s, q, p, r, t);
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
    sums[0] = forward<true>(g, w, alpha, s, as, p, r, t);
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

double multiplyRows(const Grid& grid, const PressureSystem& system, const double* s, double* q,
                    const Row* first, const Row* last) {
  return multiplyRange(grid, system, s, q, first, last);
}

double updateRow(const Row& row, double alpha, const double* s, const double* q, double* p,
                 double* r) {
  return updateRowImpl(row, alpha, s, q, p, r);
}

double dotRow(const Row& row, const double* r, const double* z) {
  return dotRowImpl(row, r, z);
}

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
  const int rowsPerWave = w.rowsPerWave > 0
                              ? std::min(w.rowsPerWave, PcgWorkspace::kWaveRows)
                              : (g.cells() <= kPairedSweepCells ? PcgWorkspace::kWaveRows : 1);
  findWaves(w.rows, rowsPerWave, w);
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
  if (w.preconditioner == FluidPreconditioner::kMultigrid) {
    return solveWithMultigrid(g, A, slab.k0, slab.k1, pp, bNorm, tol, maxIterations, comm, w);
  }
  buildPreconditioner(g, A, slab, w);
  if (comm && comm->size() > 1) {
    mergedReductions(g, A, slab, comm, w, pp, bNorm, tol, maxIterations,
                     kBytesPerCellIteration + 24, activeCells, out);
    return out;
  }
  forward<false>(g, w, 0.0, s, q, pp, r, w.t.data());
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
    double rr = forward<true>(g, w, alpha, s, q, pp, r, w.t.data());
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
