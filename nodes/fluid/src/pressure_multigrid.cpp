#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "parallel.hpp"
#include "pressure.hpp"

// The multigrid-preconditioned CG: the plain preconditioned CG with z = M^-1 r one W-cycle
// (multigrid.hpp). Every pass runs over the slab's planes on the solver's threads; a dot product
// is summed per plane, each plane in its row order, then over the planes in their order, so the
// thread count changes no bit.

namespace vrflow::fluid::detail {
namespace {

using Row = PcgWorkspace::Row;

// Calls f(plane, first row, last row) for each plane of the slab holding unknowns, cut into one
// run of planes per thread, and returns the sum of f's results in plane order.
template <typename F>
double overPlanes(PcgWorkspace& w, const Workers& workers, F&& f) {
  const std::size_t planes = w.planeRows.size() - 1;
  workers.forRanges(
      workers.threads(), planes, [&](std::size_t, std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end; ++k) {
          w.planeSums[k] = f(w.rows.data() + w.planeRows[k], w.rows.data() + w.planeRows[k + 1]);
        }
      });
  double sum = 0.0;
  for (std::size_t k = 0; k < planes; ++k) sum += w.planeSums[k];
  return sum;
}

// The first row of each plane of [k0, k1) in w.rows (rows are in plane order).
void findPlaneRows(PcgWorkspace& w, int k0, int k1) {
  const auto planes = static_cast<std::size_t>(k1 - k0);
  w.planeRows.assign(planes + 1, w.rows.size());
  for (std::size_t r = w.rows.size(); r-- > 0;) {
    w.planeRows[static_cast<std::size_t>(w.rows[r].k - k0)] = r;
  }
  for (std::size_t k = planes; k-- > 0;) {
    w.planeRows[k] = std::min(w.planeRows[k], w.planeRows[k + 1]);
  }
  w.planeSums.assign(planes, 0.0);
}

}  // namespace

PcgOutcome solveWithMultigrid(const Grid& g, const PressureSystem& A, int k0, int k1, double* p,
                              double bNorm, double tol, int maxIterations, BlockComm* comm,
                              PcgWorkspace& w) {
  const Workers one(1);
  const Workers& workers = w.workers ? *w.workers : one;
  const int planeSize = g.nx * g.ny;
  PcgOutcome out;
  findPlaneRows(w, k0, k1);
  w.multigrid.build(g, A, k0, k1, workers);
  double* r = w.r.data();
  double* z = w.z.data();
  double* s = w.s.data();
  double* q = w.q.data();
  const auto dot = [&](const double* a, const double* b) {
    return overPlanes(w, workers, [&](const Row* first, const Row* last) {
      double sum = 0.0;
      for (const Row* row = first; row != last; ++row) sum += dotRow(*row, a, b);
      return sum;
    });
  };
  const auto sumOver = [&](double local) { return comm ? comm->sum(local) : local; };

  // Bytes streamed per iteration and cell of the rows holding unknowns, if nothing stayed in
  // cache (an estimate): the product 48, the update of p and r 48, r.z 16, the direction 24;
  // the cycle's fine level 328 (copies in and out 32, the first sweep 24, three sweeps 64 each,
  // the residual with the restriction 56, the interpolation 24), and its coarse levels, visited
  // twice per cycle at an eighth of the size, a quarter of that again.
  constexpr std::uint64_t kBytesPerCellIteration = 48 + 48 + 16 + 24 + 328 + 328 / 4;
  std::uint64_t activeCells = 0;
  for (const Row& row : w.rows) activeCells += static_cast<std::uint64_t>(row.i1 - row.i0 + 1);

  w.multigrid.apply(r, z, workers);
  double rho = sumOver(dot(r, z));
  workers.forRanges(workers.threads(), w.rows.size(),
                    [&](std::size_t, std::size_t begin, std::size_t end) {
                      for (std::size_t i = begin; i < end; ++i) {
                        const Row& row = w.rows[i];
                        const std::size_t n = static_cast<std::size_t>(row.i1 - row.i0) + 1;
                        for (std::size_t c = row.c; c < row.c + n; ++c) s[c] = z[c];
                      }
                    });
  double rNorm = bNorm;
  std::vector<double> sums(2);
  for (int it = 1; it <= maxIterations; ++it) {
    if (comm) comm->exchangeHalo(w.s, planeSize, g.nz, k0, k1, 1);
    const double sq = sumOver(overPlanes(w, workers, [&](const Row* first, const Row* last) {
      return multiplyRows(g, A, s, q, first, last);
    }));
    if (sq <= 0.0) break;  // breakdown: no descent left (round-off at convergence)
    const double alpha = rho / sq;
    double rr = overPlanes(w, workers, [&](const Row* first, const Row* last) {
      double sum = 0.0;
      for (const Row* row = first; row != last; ++row) sum += updateRow(*row, alpha, s, q, p, r);
      return sum;
    });
    out.iterations = it;
    out.bytesTouched += kBytesPerCellIteration * activeCells;
    // One block tests convergence before the cycle (the last one is saved); several sum
    // |r|^2 and r.z in one reduction, the cycle run before the test.
    if (!comm) {
      rNorm = std::sqrt(rr);
      if (rNorm <= tol * bNorm) break;
    }
    w.multigrid.apply(r, z, workers);
    double rhoNew = dot(r, z);
    if (comm) {
      sums[0] = rr;
      sums[1] = rhoNew;
      comm->sum(sums);
      rNorm = std::sqrt(sums[0]);
      rhoNew = sums[1];
      if (rNorm <= tol * bNorm) break;
    }
    const double beta = rhoNew / rho;
    rho = rhoNew;
    workers.forRanges(workers.threads(), w.rows.size(),
                      [&](std::size_t, std::size_t begin, std::size_t end) {
                        for (std::size_t i = begin; i < end; ++i) {
                          const Row& row = w.rows[i];
                          const std::size_t n = static_cast<std::size_t>(row.i1 - row.i0) + 1;
                          for (std::size_t c = row.c; c < row.c + n; ++c) s[c] = z[c] + beta * s[c];
                        }
                      });
  }
  out.residual = rNorm / bNorm;
  out.converged = out.residual <= tol;
  return out;
}

}  // namespace vrflow::fluid::detail
