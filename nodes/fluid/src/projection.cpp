#include <algorithm>
#include <chrono>
#include <cmath>

#include "solver_impl.hpp"

namespace vrflow::fluid {

void FluidSolver::Impl::project(double dt) {
  const std::size_t n = grid.cells();
  auto& A = system;
  // The system is built on this block's cells and read one plane beyond them.
  const std::size_t plane = static_cast<std::size_t>(grid.nx) * grid.ny;
  const auto cFrom =
      static_cast<std::ptrdiff_t>(plane * static_cast<std::size_t>(std::max(0, k0 - 1)));
  const auto cTo =
      static_cast<std::ptrdiff_t>(plane * static_cast<std::size_t>(std::min(grid.nz, k1 + 1)));
  // The block's planes are written below, every cell (zero where no unknown); the plane beyond
  // each side is cleared here.
  const auto own0 = static_cast<std::ptrdiff_t>(plane * static_cast<std::size_t>(k0));
  const auto own1 = static_cast<std::ptrdiff_t>(plane * static_cast<std::size_t>(k1));
  for (auto* v : {&A.diag, &A.ax, &A.ay, &A.az, &rhs}) {
    v->resize(n);
    std::fill(v->begin() + cFrom, v->begin() + own0, 0.0);
    std::fill(v->begin() + own1, v->begin() + cTo, 0.0);
  }
  const double h = grid.h;
  lastDt = dt;
  stats.targetDivergence = -settings.volumeCorrection * (1.0 - stats.particleDensity) / dt;
  exchange(u[2], 2, 1);  // the w faces above this block's top plane
  const int dims[3] = {grid.nx, grid.ny, grid.nz};
  // Each cell writes its own row of the system: planes are independent.
  forPlanes(k0, k1, [&](int k) {
    for (int j = 0; j < grid.ny; ++j) {
      for (int i = 0; i < grid.nx; ++i) {
        const std::size_t c = grid.cell(i, j, k);
        double diag = 0.0, off[3] = {0.0, 0.0, 0.0};
        if (!unknown(c)) {
          A.diag[c] = A.ax[c] = A.ay[c] = A.az[c] = rhs[c] = 0.0;
          continue;
        }
        rhs[c] = -((u[0][grid.face(0, i + 1, j, k)] - u[0][grid.face(0, i, j, k)]) +
                   (u[1][grid.face(1, i, j + 1, k)] - u[1][grid.face(1, i, j, k)]) +
                   (u[2][grid.face(2, i, j, k + 1)] - u[2][grid.face(2, i, j, k)])) /
                 h;
        rhs[c] += divTarget[c] / dt;
        const int idx[3] = {i, j, k};
        for (int a = 0; a < 3; ++a) {
          for (int side = -1; side <= 1; side += 2) {
            const int m = idx[a] + side;
            if (m < 0 || m >= dims[a]) continue;  // wall: Neumann, no coefficient
            const std::size_t nbr = side > 0 ? c + stride(a) : c - stride(a);
            if (solid(nbr)) continue;  // a kinematic body: a moving wall, like the walls
            const double rho =
                unknown(nbr) ? 0.5 * (cellDensity[c] + cellDensity[nbr]) : cellDensity[c];
            const double beta = dt / (rho * h * h);
            diag += unknown(nbr) ? beta : beta / theta[c];
            if (side > 0 && unknown(nbr)) off[a] = -beta;
          }
        }
        A.diag[c] = diag;
        A.ax[c] = off[0];
        A.ay[c] = off[1];
        A.az[c] = off[2];
      }
    }
  });
  exchangeCells(A.az);  // the product needs the lower block's couplings to this block
  const auto start = std::chrono::steady_clock::now();
  const auto outcome = detail::solvePressure(grid, A, rhs, pressure, settings.cgTolerance,
                                             settings.cgMaxIterations, comm, pcg);
  stats.pressureSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  exchangeCells(pressure);
  stats.cgIterations = outcome.iterations;
  stats.cgResidual = outcome.residual;
  stats.cgConverged = outcome.converged;
  stats.bytesTouched = outcome.bytesTouched;
  // Subtract the pressure gradient on every interior face next to an unknown cell.
  for (int a = 0; a < 3; ++a) {
    forFacesNearMatterThreaded(a, [&](std::size_t f, int i, int j, int k) {
      if (onWall(a, i, j, k)) return;
      const std::size_t hi = grid.cell(i, j, k);
      const std::size_t lo = hi - stride(a);
      const bool ulo = unknown(lo), uhi = unknown(hi);
      if ((!ulo && !uhi) || solid(lo) || solid(hi)) return;
      const double rho = (ulo && uhi) ? 0.5 * (cellDensity[lo] + cellDensity[hi])
                                      : (ulo ? cellDensity[lo] : cellDensity[hi]);
      // Next to air, p = 0 lies theta cells from the unknown cell's centre.
      const double gap = (ulo && uhi) ? 1.0 : (ulo ? theta[lo] : theta[hi]);
      const double plo = ulo ? pressure[lo] : 0.0, phi = uhi ? pressure[hi] : 0.0;
      u[a][f] -= dt / (rho * h) * (phi - plo) / gap;
    });
  }
}

void FluidSolver::Impl::measureDivergence() {
  exchange(u[2], 2, 1);
  double worst = 0.0, fluid = 0.0, body = 0.0;
  for (int k = k0; k < k1; ++k) {
    for (int j = 0; j < grid.ny; ++j) {
      for (int i = 0; i < grid.nx; ++i) {
        const std::size_t c = grid.cell(i, j, k);
        if (kind[c] == detail::kBody) body += 1;
        if (kind[c] != detail::kLiquid) continue;
        fluid += 1;
        const double div = ((u[0][grid.face(0, i + 1, j, k)] - u[0][grid.face(0, i, j, k)]) +
                            (u[1][grid.face(1, i, j + 1, k)] - u[1][grid.face(1, i, j, k)]) +
                            (u[2][grid.face(2, i, j, k + 1)] - u[2][grid.face(2, i, j, k)])) *
                           invH;
        worst = std::max(worst, std::abs(div - divTarget[c] / lastDt));
      }
    }
  }
  if (comm) {
    std::vector<double> both{fluid, body};
    comm->sum(both);
    fluid = both[0];
    body = both[1];
  }
  stats.fluidCells = static_cast<int>(fluid);
  stats.bodyCells = static_cast<int>(body);
  double speed = 0.0;
  for (int a = 0; a < 3; ++a) {
    forFacesNearMatter(a, [&](std::size_t f, int i, int j, int k) {
      if (onWall(a, i, j, k)) return;
      const std::size_t hi = grid.cell(i, j, k);
      const std::size_t lo = hi - stride(a);
      if (kind[lo] != detail::kLiquid && kind[hi] != detail::kLiquid) return;
      speed = std::max(speed, std::abs(u[a][f]));
    });
  }
  // Both maxima in one reduction.
  if (comm) {
    std::vector<double> both{worst, speed};
    comm->max(both);
    worst = both[0];
    speed = both[1];
  }
  maxDiv = worst;
  stats.maxSpeed = speed;
}

void FluidSolver::Impl::markProjectedFaces() {
  for (int a = 0; a < 3; ++a) {
    const auto ps = static_cast<std::ptrdiff_t>(planeSize(a));
    std::fill(valid[a].begin() + ps * k0, valid[a].begin() + ps * kEnd(a), 0);
    forFacesNearMatterThreaded(a, [&](std::size_t f, int i, int j, int k) {
      const int along = a == 0 ? i : a == 1 ? j : k;
      // Projected faces and the faces of kinematic bodies keep their values.
      bool touches = false;
      if (along > 0) {
        const std::size_t lo = grid.cell(i, j, k) - stride(a);
        touches = unknown(lo) || solid(lo);
      }
      if (along < grid.fdim(a, a) - 1) {
        const std::size_t hi = grid.cell(i, j, k);
        touches = touches || unknown(hi) || solid(hi);
      }
      valid[a][f] = touches ? 1 : 0;
    });
  }
}

}  // namespace vrflow::fluid
