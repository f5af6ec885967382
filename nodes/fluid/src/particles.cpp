#include <algorithm>
#include <cmath>

#include "solver_impl.hpp"
#include "transfer.hpp"

namespace vrflow::fluid {

namespace {
constexpr int kHaloForParticles = 3;  // planes of velocity a block's particles may sample
constexpr int kParticleRecord = 6;    // position and velocity
// Fewer particles than this are sorted on one thread.
constexpr std::size_t kThreadedSortParticles = 4096;
}  // namespace

void FluidSolver::Impl::migrate() {
  // One block owns every plane: nothing leaves it (a pass over the particles less, twice a step).
  if (!comm || comm->size() == 1) return;
  const int n = comm->size();
  std::vector<std::vector<double>> out(static_cast<std::size_t>(n));
  std::size_t keep = 0;
  const std::size_t count = pos.size() / 3;
  for (std::size_t p = 0; p < count; ++p) {
    const int k = planeOf(&pos[3 * p]);
    if (k >= k0 && k < k1) {
      if (keep != p) {
        for (int d = 0; d < 3; ++d) {
          pos[3 * keep + d] = pos[3 * p + d];
          vel[3 * keep + d] = vel[3 * p + d];
        }
      }
      ++keep;
      continue;
    }
    auto& o = out[static_cast<std::size_t>(blockOfPlane(grid.nz, n, k))];
    o.insert(o.end(), &pos[3 * p], &pos[3 * p] + 3);
    o.insert(o.end(), &vel[3 * p], &vel[3 * p] + 3);
  }
  pos.resize(3 * keep);
  vel.resize(3 * keep);
  const auto in = comm->exchange(out, kParticleRecord);
  for (std::size_t r = 0; r + kParticleRecord <= in.size(); r += kParticleRecord) {
    pos.insert(pos.end(), &in[r], &in[r] + 3);
    vel.insert(vel.end(), &in[r + 3], &in[r + 3] + 3);
  }
}

void FluidSolver::Impl::sortParticles() {
  // This block's particles all lie in its slab (cellOf clamps as planeOf does in migrate), so
  // only the slab's cells are counted; the others keep their zero counts.
  const std::size_t n = pos.size() / 3;
  const std::size_t plane = static_cast<std::size_t>(grid.nx) * grid.ny;
  const std::size_t c0 = plane * static_cast<std::size_t>(k0),
                    c1 = plane * static_cast<std::size_t>(k1);
  const int parts = n >= kThreadedSortParticles ? workers->threads() : 1;
  if (!cellsKnown) {
    sortCell.resize(n);
    workers->forRanges(parts, n, [&](std::size_t, std::size_t p0, std::size_t p1) {
      for (std::size_t p = p0; p < p1; ++p) sortCell[p] = clampedCell(&pos[3 * p]);
    });
  }
  sortStart.resize(grid.cells() + 1);
  sortStart[c0] = 0;
  posScratch.resize(pos.size());
  velScratch.resize(vel.size());
  // Each part counts its particles per cell; the counts then become the first place of each
  // part's particles in each cell (part 0's first: the serial order), and each part moves its own.
  partCounts.resize(static_cast<std::size_t>(parts));
  workers->forRanges(parts, n, [&](std::size_t part, std::size_t p0, std::size_t p1) {
    auto& count = partCounts[part];
    count.assign(c1 - c0, 0);
    for (std::size_t p = p0; p < p1; ++p) ++count[sortCell[p] - c0];
  });
  for (std::size_t c = c0; c < c1; ++c) {
    std::size_t at = sortStart[c];
    for (auto& count : partCounts) {
      const std::uint32_t here = count[c - c0];
      count[c - c0] = static_cast<std::uint32_t>(at);
      at += here;
    }
    particlesInCell[c] = static_cast<int>(at - sortStart[c]);
    sortStart[c + 1] = at;
  }
  planeStart.resize(static_cast<std::size_t>(k1 - k0) + 1);
  for (int k = k0; k <= k1; ++k) {
    planeStart[static_cast<std::size_t>(k - k0)] = sortStart[plane * static_cast<std::size_t>(k)];
  }
  workers->forRanges(parts, n, [&](std::size_t part, std::size_t p0, std::size_t p1) {
    auto& next = partCounts[part];
    for (std::size_t p = p0; p < p1; ++p) {
      const std::size_t to = next[sortCell[p] - c0]++;
      for (int d = 0; d < 3; ++d) {
        posScratch[3 * to + d] = pos[3 * p + d];
        velScratch[3 * to + d] = vel[3 * p + d];
      }
    }
  });
  pos.swap(posScratch);
  vel.swap(velScratch);
  cellsKnown = false;
}

void FluidSolver::Impl::pushParticlesOut(const std::vector<PreparedBody>& bodies) {
  if (bodies.empty()) return;
  // Per cell, the bodies whose bounds (one cell wider) reach it, in body order: a particle is
  // tested against those only (a net's hundreds of nodes lie over one layer of cells).
  const std::size_t cells = grid.cells();
  bodiesAt.assign(cells + 1, 0);
  const double o[3] = {grid.ox, grid.oy, grid.oz};
  const int n[3] = {grid.nx, grid.ny, grid.nz};
  auto forCellsNear = [&](const PreparedBody& body, auto&& f) {
    int lo[3], hi[3];
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::max(0, static_cast<int>(std::floor((body.bounds.min[d] - o[d]) * invH)) - 1);
      hi[d] =
          std::min(n[d] - 1, static_cast<int>(std::floor((body.bounds.max[d] - o[d]) * invH)) + 1);
    }
    for (int k = lo[2]; k <= hi[2]; ++k) {
      for (int j = lo[1]; j <= hi[1]; ++j) {
        for (int i = lo[0]; i <= hi[0]; ++i) f(grid.cell(i, j, k));
      }
    }
  };
  for (const auto& body : bodies) forCellsNear(body, [&](std::size_t c) { ++bodiesAt[c + 1]; });
  for (std::size_t c = 0; c < cells; ++c) bodiesAt[c + 1] += bodiesAt[c];
  bodyList.resize(bodiesAt[cells]);
  {
    std::vector<std::uint32_t>& next = bodyListFill;
    next.assign(bodiesAt.begin(), bodiesAt.end() - 1);
    for (std::size_t b = 0; b < bodies.size(); ++b) {
      forCellsNear(bodies[b],
                   [&](std::size_t c) { bodyList[next[c]++] = static_cast<std::uint32_t>(b); });
    }
  }
  const std::size_t count = pos.size() / 3;
  for (std::size_t p = 0; p < count; ++p) {
    double* x = &pos[3 * p];
    std::size_t c;
    if (cellsKnown) {
      c = sortCell[p];
    } else {
      int i, j, k;
      if (!cellOf(x, i, j, k)) continue;
      c = grid.cell(i, j, k);
    }
    if (bodiesAt[c] == bodiesAt[c + 1]) continue;
    // Every body whose bounds hold a point of cell c is on c's list. A push that carries the
    // particle out of c ends the list: the bodies after the one that pushed are then all tested.
    for (std::uint32_t e = bodiesAt[c]; e < bodiesAt[c + 1]; ++e) {
      const std::size_t b = bodyList[e];
      if (!detail::inBounds(bodies[b].bounds, x)) continue;
      detail::pushOut(bodies[b], x, 0.25 * grid.h);
      clampToDomain(x);
      if (clampedCell(x) == c) continue;
      for (std::size_t rest = b + 1; rest < bodies.size(); ++rest) {
        if (!detail::inBounds(bodies[rest].bounds, x)) continue;
        detail::pushOut(bodies[rest], x, 0.25 * grid.h);
        clampToDomain(x);
      }
      break;
    }
    if (cellsKnown) sortCell[p] = clampedCell(x);
  }
}

void FluidSolver::Impl::particlesToGrid() {
  // This block's particles reach face planes k0 - 1 to k1.
  for (int a = 0; a < 3; ++a) {
    const std::size_t ps = 2 * static_cast<std::size_t>(planeSize(a));
    const auto from =
        static_cast<std::ptrdiff_t>(ps * static_cast<std::size_t>(std::max(0, k0 - 1)));
    const auto to = static_cast<std::ptrdiff_t>(
        ps * static_cast<std::size_t>(std::min(grid.fdim(a, 2), k1 + 1)));
    std::fill(acc[a].begin() + from, acc[a].begin() + to, 0.0);
  }
  splatParticles();
  for (int a = 0; a < 3; ++a) {
    if (comm) comm->addHalo(acc[a], 2 * planeSize(a), grid.fdim(a, 2), k0, k1);
    // Faces of other blocks read zero (this block's are all written below).
    const auto ps = static_cast<std::ptrdiff_t>(planeSize(a));
    std::fill(u[a].begin(), u[a].begin() + ps * k0, 0.0);
    std::fill(u[a].begin() + ps * kEnd(a), u[a].end(), 0.0);
    const double* in = acc[a].data();
    forOwnFacesThreaded(a, [&](std::size_t f, int, int, int) {
      const double w = in[2 * f + 1];
      if (w > 1e-9) {
        u[a][f] = in[2 * f] / w;
        valid[a][f] = 1;
      } else {
        u[a][f] = 0.0;
        valid[a][f] = 0;
      }
    });
  }
}

void FluidSolver::Impl::splatParticles() {
  // Threads take consecutive runs of planes (particles are sorted by cell, so a run of planes is
  // a range of particles). A particle in cell plane k adds to face planes k - 1 to k + 1, so
  // around a border b between two runs, face planes b - 1 and b get sums from both: each run
  // leaves those out, and afterwards the particles of planes b - 2 to b + 1 add to them alone,
  // in particle order. Every face then sums the same terms in the same order as one thread: the
  // same bits whatever the thread count.
  constexpr int kMinPlanes = 4;  // keeps the borders' plane ranges apart
  const int runs = std::max(1, std::min(settings.threads, (k1 - k0) / kMinPlanes));
  const std::size_t n = pos.size() / 3;
  std::vector<int> border(static_cast<std::size_t>(runs) + 1, k0);
  border.back() = k1;
  for (int t = 1; t < runs; ++t) {
    // The first plane at which t / runs of the particles lie below, kept kMinPlanes apart.
    const std::size_t want = n * static_cast<std::size_t>(t) / static_cast<std::size_t>(runs);
    int k = border[static_cast<std::size_t>(t) - 1] + kMinPlanes;
    while (k < k1 - kMinPlanes * (runs - t) && planeStart[static_cast<std::size_t>(k - k0)] < want)
      ++k;
    border[static_cast<std::size_t>(t)] = k;
  }
  auto first = [&](int k) { return planeStart[static_cast<std::size_t>(k - k0)]; };
  constexpr int kAll = 1 << 29;  // "every plane"
  workers->forRanges(runs, static_cast<std::size_t>(runs),
                     [&](std::size_t r, std::size_t, std::size_t) {
                       const int lo = border[r], hi = border[r + 1];
                       splatRange(first(lo), first(hi), r == 0 ? -kAll : lo + 1,
                                  static_cast<int>(r) + 1 == runs ? kAll : hi - 2);
                     });
  for (int t = 1; t < runs; ++t) {
    const int b = border[static_cast<std::size_t>(t)];
    splatRange(first(b - 2), first(b + 2), b - 1, b);
  }
}

VRFLOW_FLUID_HOT void FluidSolver::Impl::splatRange(std::size_t p0, std::size_t p1, int planeLo,
                                                    int planeHi) {
  const detail::Lattice lattice(grid);
  double* sums[3] = {acc[0].data(), acc[1].data(), acc[2].data()};
  const double* x = pos.data() + 3 * p0;
  const double* v = vel.data() + 3 * p0;
  for (std::size_t p = p0; p < p1; ++p, x += 3, v += 3) {
    detail::Located c;
    detail::locate(lattice, x, c);
    const int zc = c.centreBase[2] - planeLo, zf = c.faceBase[2] - planeLo;
    const int span = planeHi - planeLo;
    detail::splat(sums[0], detail::stencilOf(lattice, 0, c), v[0], zc, span);
    detail::splat(sums[1], detail::stencilOf(lattice, 1, c), v[1], zc, span);
    detail::splat(sums[2], detail::stencilOf(lattice, 2, c), v[2], zf, span);
  }
}

void FluidSolver::Impl::gridToParticlesAndAdvect(double dt) {
  // (new velocity, change) per face, interleaved: the FLIP update needs both at the same
  // stencil, and the pairs interpolate together. Built on this block's faces; the planes its
  // particles can sample beyond them come from the neighbours.
  for (int a = 0; a < 3; ++a) {
    const std::size_t ps = static_cast<std::size_t>(planeSize(a));
    double* out = acc[a].data();
    const double* un = u[a].data();
    const double* uo = uOld[a].data();
    for (std::size_t f = ps * static_cast<std::size_t>(k0);
         f < ps * static_cast<std::size_t>(kEnd(a)); ++f) {
      out[2 * f] = un[f];
      out[2 * f + 1] = un[f] - uo[f];
    }
    if (comm) {
      comm->exchangeHalo(acc[a], 2 * planeSize(a), grid.fdim(a, 2), k0, k1, kHaloForParticles);
    }
  }
  sampleAndAdvectParticles(dt);
}

void FluidSolver::Impl::sampleAndAdvectParticles(double dt) {
  const std::size_t n = pos.size() / 3;
  const bool storeCells = !comm || comm->size() == 1;
  if (storeCells) sortCell.resize(n);
  posScratch.resize(pos.size());
  // Each particle's update reads the grid and writes the particle only: any split gives the
  // same bits.
  workers->forRanges(settings.threads, n, [&](std::size_t, std::size_t p0, std::size_t p1) {
    sampleAndAdvectRange(dt, p0, p1, storeCells);
  });
  cellsKnown = storeCells;
}

VRFLOW_FLUID_HOT void FluidSolver::Impl::sampleAndAdvectRange(double dt, std::size_t p0,
                                                              std::size_t p1, bool storeCells) {
  const detail::Lattice lattice(grid);
  const double* pairs[3] = {acc[0].data(), acc[1].data(), acc[2].data()};
  const double flip = settings.flipRatio, pic = 1.0 - flip;
  const double halfDt = 0.5 * dt;
  // clampToDomain()'s bounds, computed once.
  const double eps = 1e-3 * grid.h;
  const double o[3] = {grid.ox, grid.oy, grid.oz};
  const int cells[3] = {grid.nx, grid.ny, grid.nz};
  double lo[3], hi[3];
  for (int d = 0; d < 3; ++d) {
    lo[d] = o[d] + eps;
    hi[d] = o[d] + cells[d] * grid.h - eps;
  }
  auto clamp = [&](double* y) {
    for (int d = 0; d < 3; ++d) y[d] = std::min(std::max(y[d], lo[d]), hi[d]);
  };
  // Two passes (velocities and midpoints, then positions) rather than one: within a particle
  // the second interpolation waits for the first, and a pass of short independent chains
  // keeps more particles in flight.
  double* midpoints = posScratch.data();
  for (std::size_t p = p0; p < p1; ++p) {
    const double* x = &pos[3 * p];
    double* v = &vel[3 * p];
    detail::Located c;
    detail::locate(lattice, x, c);
    const detail::Pair g0 = detail::gatherPair(pairs[0], detail::stencilOf(lattice, 0, c));
    const detail::Pair g1 = detail::gatherPair(pairs[1], detail::stencilOf(lattice, 1, c));
    const detail::Pair g2 = detail::gatherPair(pairs[2], detail::stencilOf(lattice, 2, c));
    v[0] = flip * (v[0] + g0[1]) + pic * g0[0];
    v[1] = flip * (v[1] + g1[1]) + pic * g1[0];
    v[2] = flip * (v[2] + g2[1]) + pic * g2[0];
    // Midpoint (RK2) through the divergence-free grid velocity.
    double* mid = midpoints + 3 * p;
    mid[0] = x[0] + halfDt * g0[0];
    mid[1] = x[1] + halfDt * g1[0];
    mid[2] = x[2] + halfDt * g2[0];
    clamp(mid);
  }
  for (std::size_t p = p0; p < p1; ++p) {
    double* x = &pos[3 * p];
    detail::Located c;
    detail::locate(lattice, midpoints + 3 * p, c);
    x[0] += dt * detail::gatherPair(pairs[0], detail::stencilOf(lattice, 0, c))[0];
    x[1] += dt * detail::gatherPair(pairs[1], detail::stencilOf(lattice, 1, c))[0];
    x[2] += dt * detail::gatherPair(pairs[2], detail::stencilOf(lattice, 2, c))[0];
    clamp(x);
    if (storeCells) sortCell[p] = clampedCell(x);
  }
}

}  // namespace vrflow::fluid
