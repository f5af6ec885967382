#include "pressure.hpp"

#include <cmath>
#include <cstddef>

namespace vrflow::fluid::detail {
namespace {

constexpr double kTau = 0.97;    // modified incomplete Cholesky blend (Bridson)
constexpr double kSigma = 0.25;  // safety: fall back to the diagonal when the pivot collapses

struct Slab {
  int k0 = 0, k1 = 0;
  std::size_t c0 = 0, c1 = 0;
};

double localDot(const std::vector<double>& a, const std::vector<double>& b, const Slab& s) {
  double sum = 0.0;
  for (std::size_t c = s.c0; c < s.c1; ++c) sum += a[c] * b[c];
  return sum;
}

double dot(const std::vector<double>& a, const std::vector<double>& b, const Slab& s,
           BlockComm* comm) {
  const double local = localDot(a, b, s);
  return comm ? comm->sum(local) : local;
}

// q = A s on the slab; s must hold valid halo planes k0 - 1 and k1.
void multiply(const Grid& g, const PressureSystem& A, const std::vector<double>& s,
              std::vector<double>& q, const Slab& slab) {
  const std::size_t sx = 1, sy = static_cast<std::size_t>(g.nx),
                    sz = static_cast<std::size_t>(g.nx) * g.ny;
  for (int k = slab.k0; k < slab.k1; ++k) {
    for (int j = 0; j < g.ny; ++j) {
      std::size_t c = g.cell(0, j, k);
      for (int i = 0; i < g.nx; ++i, ++c) {
        if (A.diag[c] == 0.0) {
          q[c] = 0.0;
          continue;
        }
        double v = A.diag[c] * s[c];
        if (i + 1 < g.nx) v += A.ax[c] * s[c + sx];
        if (i > 0) v += A.ax[c - sx] * s[c - sx];
        if (j + 1 < g.ny) v += A.ay[c] * s[c + sy];
        if (j > 0) v += A.ay[c - sy] * s[c - sy];
        if (k + 1 < g.nz) v += A.az[c] * s[c + sz];
        if (k > 0) v += A.az[c - sz] * s[c - sz];
        q[c] = v;
      }
    }
  }
}

// MIC(0) of the slab's own block of A: couplings that leave the slab are dropped.
void buildPreconditioner(const Grid& g, const PressureSystem& A, const Slab& slab,
                         std::vector<double>& pc, std::vector<double>& azLocal) {
  const std::size_t sy = static_cast<std::size_t>(g.nx), sz = sy * g.ny;
  azLocal.assign(A.az.size(), 0.0);
  for (int k = slab.k0; k + 1 < slab.k1; ++k) {
    const std::size_t c0 = g.cell(0, 0, k);
    for (std::size_t c = c0; c < c0 + sz; ++c) azLocal[c] = A.az[c];
  }
  for (int k = slab.k0; k < slab.k1; ++k) {
    for (int j = 0; j < g.ny; ++j) {
      std::size_t c = g.cell(0, j, k);
      for (int i = 0; i < g.nx; ++i, ++c) {
        if (A.diag[c] == 0.0) {
          pc[c] = 0.0;
          continue;
        }
        double e = A.diag[c];
        if (i > 0) {
          const std::size_t n = c - 1;
          const double a = A.ax[n] * pc[n];
          e -= a * a + kTau * A.ax[n] * (A.ay[n] + azLocal[n]) * pc[n] * pc[n];
        }
        if (j > 0) {
          const std::size_t n = c - sy;
          const double a = A.ay[n] * pc[n];
          e -= a * a + kTau * A.ay[n] * (A.ax[n] + azLocal[n]) * pc[n] * pc[n];
        }
        if (k > slab.k0) {
          const std::size_t n = c - sz;
          const double a = azLocal[n] * pc[n];
          e -= a * a + kTau * azLocal[n] * (A.ax[n] + A.ay[n]) * pc[n] * pc[n];
        }
        if (e < kSigma * A.diag[c]) e = A.diag[c];
        pc[c] = 1.0 / std::sqrt(e);
      }
    }
  }
}

// z = M^-1 r with M the MIC(0) factor L L^T; `t` is scratch.
void applyPreconditioner(const Grid& g, const PressureSystem& A, const std::vector<double>& az,
                         const std::vector<double>& pc, const std::vector<double>& r,
                         std::vector<double>& t, std::vector<double>& z, const Slab& slab) {
  const std::size_t sy = static_cast<std::size_t>(g.nx), sz = sy * g.ny;
  for (int k = slab.k0; k < slab.k1; ++k) {
    for (int j = 0; j < g.ny; ++j) {
      std::size_t c = g.cell(0, j, k);
      for (int i = 0; i < g.nx; ++i, ++c) {
        if (A.diag[c] == 0.0) {
          t[c] = 0.0;
          continue;
        }
        double v = r[c];
        if (i > 0) v -= A.ax[c - 1] * pc[c - 1] * t[c - 1];
        if (j > 0) v -= A.ay[c - sy] * pc[c - sy] * t[c - sy];
        if (k > slab.k0) v -= az[c - sz] * pc[c - sz] * t[c - sz];
        t[c] = v * pc[c];
      }
    }
  }
  for (int k = slab.k1 - 1; k >= slab.k0; --k) {
    for (int j = g.ny - 1; j >= 0; --j) {
      std::size_t c = g.cell(g.nx - 1, j, k);
      for (int i = g.nx - 1; i >= 0; --i, --c) {
        if (A.diag[c] == 0.0) {
          z[c] = 0.0;
          continue;
        }
        double v = t[c];
        if (i + 1 < g.nx) v -= A.ax[c] * pc[c] * z[c + 1];
        if (j + 1 < g.ny) v -= A.ay[c] * pc[c] * z[c + sy];
        if (k + 1 < slab.k1) v -= az[c] * pc[c] * z[c + sz];
        z[c] = v * pc[c];
      }
    }
  }
}

}  // namespace

PcgOutcome solvePressure(const Grid& g, const PressureSystem& A, const std::vector<double>& b,
                         std::vector<double>& p, double tol, int maxIterations, BlockComm* comm) {
  const std::size_t n = g.cells();
  const int planeSize = g.nx * g.ny;
  Slab slab;
  if (comm) {
    slabOf(g.nz, comm->rank(), comm->size(), slab.k0, slab.k1);
  } else {
    slab.k1 = g.nz;
  }
  slab.c0 = static_cast<std::size_t>(slab.k0) * planeSize;
  slab.c1 = static_cast<std::size_t>(slab.k1) * planeSize;
  const std::uint64_t slabCells = slab.c1 - slab.c0;
  // Arrays streamed per iteration: product 6, two updates 6, preconditioner 12, dot 2,
  // direction update 3 (doubles).
  constexpr std::uint64_t kArraysPerIteration = 29;

  PcgOutcome out;
  p.assign(n, 0.0);
  std::vector<double> r(b), z(n, 0.0), s(n, 0.0), q(n, 0.0), t(n, 0.0), pc(n, 0.0), azLocal;
  const double bNorm = std::sqrt(dot(r, r, slab, comm));
  if (bNorm == 0.0) return out;
  buildPreconditioner(g, A, slab, pc, azLocal);
  applyPreconditioner(g, A, azLocal, pc, r, t, z, slab);
  for (std::size_t c = slab.c0; c < slab.c1; ++c) s[c] = z[c];
  double rho = dot(r, z, slab, comm);
  double rNorm = bNorm;
  for (int it = 1; it <= maxIterations; ++it) {
    if (comm) comm->exchangeHalo(s, planeSize, g.nz, slab.k0, slab.k1, 1);
    multiply(g, A, s, q, slab);
    const double sq = dot(s, q, slab, comm);
    if (sq <= 0.0) break;  // breakdown: no descent left (round-off at convergence)
    const double alpha = rho / sq;
    double rr = 0.0;
    for (std::size_t c = slab.c0; c < slab.c1; ++c) {
      p[c] += alpha * s[c];
      r[c] -= alpha * q[c];
      rr += r[c] * r[c];
    }
    rNorm = std::sqrt(comm ? comm->sum(rr) : rr);
    out.iterations = it;
    out.bytesTouched += kArraysPerIteration * 8 * slabCells;
    if (rNorm <= tol * bNorm) break;
    applyPreconditioner(g, A, azLocal, pc, r, t, z, slab);
    const double rhoNew = dot(r, z, slab, comm);
    const double beta = rhoNew / rho;
    rho = rhoNew;
    for (std::size_t c = slab.c0; c < slab.c1; ++c) s[c] = z[c] + beta * s[c];
  }
  out.residual = rNorm / bNorm;
  out.converged = out.residual <= tol;
  return out;
}

}  // namespace vrflow::fluid::detail
