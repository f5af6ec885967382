#include <algorithm>
#include <cmath>

#include "solver_impl.hpp"

namespace vrflow::fluid {

namespace {
constexpr double kMinTheta = 0.2;  // keeps ghost-fluid coefficients (1 / theta) bounded
}  // namespace

void FluidSolver::Impl::exchangeBytes(std::vector<unsigned char>& bytes, int planeSizeBytes,
                                      int planes) {
  if (!comm) return;
  const std::size_t ps = static_cast<std::size_t>(planeSizeBytes);
  byteScratch.resize(bytes.size());
  // The received planes start as they are, so a plane no neighbour sends stays unchanged.
  for (int k : {k0 - 1, k0, k1 - 1, k1}) {
    if (k < 0 || k >= planes) continue;
    for (std::size_t c = k * ps; c < (k + 1) * ps; ++c) byteScratch[c] = bytes[c];
  }
  comm->exchangeHalo(byteScratch, planeSizeBytes, planes, k0, k1, 1);
  for (int k : {k0 - 1, k1}) {
    if (k < 0 || k >= planes) continue;
    for (std::size_t c = k * ps; c < (k + 1) * ps; ++c) {
      bytes[c] = static_cast<unsigned char>(byteScratch[c]);
    }
  }
}

void FluidSolver::Impl::exchangeWithValidity(std::vector<double>& field,
                                             std::vector<unsigned char>& flags, int a) {
  if (!comm) return;
  const std::size_t ps = static_cast<std::size_t>(planeSize(a));
  const int planes = grid.fdim(a, 2);
  haloScratch.resize(2 * field.size());
  // The received planes start as they are, so a plane no neighbour sends stays unchanged.
  for (int k : {k0 - 1, k0, k1 - 1, k1}) {
    if (k < 0 || k >= planes) continue;
    for (std::size_t f = k * ps; f < (k + 1) * ps; ++f) {
      haloScratch[2 * f] = field[f];
      haloScratch[2 * f + 1] = flags[f];
    }
  }
  comm->exchangeHalo(haloScratch, 2 * planeSize(a), planes, k0, k1, 1);
  for (int k : {k0 - 1, k1}) {
    if (k < 0 || k >= planes) continue;
    for (std::size_t f = k * ps; f < (k + 1) * ps; ++f) {
      field[f] = haloScratch[2 * f];
      flags[f] = static_cast<unsigned char>(haloScratch[2 * f + 1]);
    }
  }
}

void FluidSolver::Impl::markRowsWithMatter() {
  rowHasMatter.assign(static_cast<std::size_t>(grid.ny) * grid.nz, 0);
  for (int k = std::max(0, k0 - 1); k < std::min(grid.nz, k1 + 1); ++k) {
    for (int j = 0; j < grid.ny; ++j) {
      const unsigned char* row = kind.data() + grid.cell(0, j, k);
      unsigned char any = 0;
      for (int i = 0; i < grid.nx; ++i) any |= row[i];  // kAir is 0
      rowHasMatter[static_cast<std::size_t>(k) * grid.ny + j] = any != 0;
    }
  }
}

void FluidSolver::Impl::zeroWalls(std::vector<double>* field) const {
  for (int k = k0; k < k1; ++k) {
    for (int j = 0; j < grid.ny; ++j) {
      field[0][grid.face(0, 0, j, k)] = 0.0;
      field[0][grid.face(0, grid.nx, j, k)] = 0.0;
    }
    for (int i = 0; i < grid.nx; ++i) {
      field[1][grid.face(1, i, 0, k)] = 0.0;
      field[1][grid.face(1, i, grid.ny, k)] = 0.0;
    }
  }
  const std::size_t ps = static_cast<std::size_t>(planeSize(2));
  for (int k : {0, grid.nz}) {
    if (k < k0 || k >= kEnd(2)) continue;
    std::fill_n(field[2].begin() + static_cast<std::ptrdiff_t>(k * ps),
                static_cast<std::ptrdiff_t>(ps), 0.0);
  }
}

void FluidSolver::Impl::classify(const std::vector<PreparedBody>& bodies) {
  detail::rasterise(grid, bodies, cellBody, faceBody);
  // Kinds are read one plane beyond the slab at most.
  const std::size_t plane = static_cast<std::size_t>(grid.nx) * grid.ny;
  const std::size_t cFrom = plane * static_cast<std::size_t>(std::max(0, k0 - 1));
  const std::size_t cTo = plane * static_cast<std::size_t>(std::min(grid.nz, k1 + 1));
  for (std::size_t c = cFrom; c < cTo; ++c) {
    if (cellBody[c] >= 0) {
      const auto& body = bodies[static_cast<std::size_t>(cellBody[c])];
      kind[c] = body.kinematic ? detail::kSolid : detail::kBody;
      cellDensity[c] = body.density;
    } else {
      kind[c] = detail::kAir;
      cellDensity[c] = settings.density;
    }
  }
  for (std::size_t c = k0 * plane; c < k1 * plane; ++c) {
    if (particlesInCell[c] > 0 && kind[c] == detail::kAir) kind[c] = detail::kLiquid;
  }
  exchangeBytes(kind, grid.nx * grid.ny, grid.nz);
  dryBodiesOutOfLiquid(bodies);
  markRowsWithMatter();
  // Volume control: each liquid cell away from the surface asks for a divergence that brings
  // its particle count back to particlesPerCell (cells next to air are partly full by nature).
  divTarget.assign(kind.size(), 0.0);
  const double n0 = settings.particlesPerCell;
  const std::size_t sy = static_cast<std::size_t>(grid.nx), sz = plane;
  double total = 0, count = 0;
  for (int k = k0; k < k1; ++k) {
    for (int j = 0; j < grid.ny; ++j) {
      for (int i = 0; i < grid.nx; ++i) {
        const std::size_t c = grid.cell(i, j, k);
        if (kind[c] != detail::kLiquid) continue;
        if ((i > 0 && kind[c - 1] == detail::kAir) ||
            (i + 1 < grid.nx && kind[c + 1] == detail::kAir) ||
            (j > 0 && kind[c - sy] == detail::kAir) ||
            (j + 1 < grid.ny && kind[c + sy] == detail::kAir) ||
            (k > 0 && kind[c - sz] == detail::kAir) ||
            (k + 1 < grid.nz && kind[c + sz] == detail::kAir)) {
          continue;
        }
        total += particlesInCell[c];
        count += 1;
        const double density = std::min(2.0, particlesInCell[c] / n0);
        divTarget[c] = -settings.volumeCorrection * (1.0 - density);
      }
    }
  }
  if (comm) {
    std::vector<double> both{total, count};
    comm->sum(both);
    total = both[0];
    count = both[1];
  }
  stats.particleDensity = count > 0 ? total / (count * n0) : 1.0;
  theta.assign(kind.size(), 0.5);
  for (std::size_t c = k0 * plane; c < k1 * plane; ++c) {
    if (kind[c] != detail::kLiquid) continue;
    const double full = std::min(1.0, particlesInCell[c] / n0);
    theta[c] = std::clamp(full - 0.5, kMinTheta, 0.5);
  }
  exchangeCells(theta);
}

void FluidSolver::Impl::dryBodiesOutOfLiquid(const std::vector<PreparedBody>& bodies) {
  const std::size_t bodyCount = bodies.size();
  // Per body: (touches the liquid, has a submerged cell), doubles for the reduction over blocks.
  std::vector<double> wet(2 * bodyCount, 0.0);
  const int dims[3] = {grid.nx, grid.ny, grid.nz};
  // "Down" is the axis and sign of gravity's largest component (none without gravity: every
  // liquid neighbour then submerges a body cell, whatever side it is on).
  int downAxis = -1, downSign = 0;
  double strongest = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double g = settings.gravity[static_cast<std::size_t>(a)];
    if (std::abs(g) > strongest) {
      strongest = std::abs(g);
      downAxis = a;
      downSign = g < 0.0 ? -1 : 1;
    }
  }
  // Twice a liquid cell's particle count above particlesPerCell: its surface lies above its
  // centre (the ghost-fluid surface sits (n / n0 - 0.5) cells from it).
  const int halfFull = settings.particlesPerCell;
  // Whether the liquid cell c submerges the body cell b on its `side` (-1, +1) along axis a;
  // `face` is the face between them.
  auto submerges = [&](std::size_t c, std::size_t b, int a, int side, std::size_t face) {
    if (a != downAxis) return 2 * particlesInCell[c] > halfFull;  // beside
    if (side == downSign) return true;                            // the liquid lies on it
    return faceBody[a][face] == cellBody[b];                      // it dips into the liquid
  };
  auto mark = [&](std::size_t b, bool submerged) {
    wet[2 * b] = 1.0;
    if (submerged) wet[2 * b + 1] = 1.0;
  };
  // A body touches the liquid when one of its cells holds particles (outside the shape, inside
  // the cell) or shares a face with a liquid cell: its cells stay pressure unknowns, so the
  // liquid feels it. A body cell is submerged when it holds particles, when a liquid cell lies
  // on it, when a liquid cell beside it is more than half full (the surface there is above the
  // body cell's centre), or when the body reaches down into the liquid cell under it (the face
  // between them is the body's). A body resting on the surface, its shape above the liquid
  // cells, touches it without a submerged cell: the liquid holds it up, but the pressure there
  // is the surface's and the body gets no force. Each relation is judged by the block holding
  // the liquid cell (kinds, cellBody and faceBody are known one plane beyond the slab).
  for (int k = k0; k < k1; ++k) {
    for (int j = 0; j < grid.ny; ++j) {
      for (int i = 0; i < grid.nx; ++i) {
        const std::size_t c = grid.cell(i, j, k);
        if (kind[c] == detail::kBody && particlesInCell[c] > 0) {
          mark(static_cast<std::size_t>(cellBody[c]), true);
        }
        if (kind[c] != detail::kLiquid) continue;
        const int idx[3] = {i, j, k};
        for (int a = 0; a < 3; ++a) {
          const std::size_t below = c - stride(a), above = c + stride(a);
          if (idx[a] > 0 && kind[below] == detail::kBody) {
            mark(static_cast<std::size_t>(cellBody[below]),
                 submerges(c, below, a, -1, grid.face(a, i, j, k)));
          }
          if (idx[a] + 1 < dims[a] && kind[above] == detail::kBody) {
            mark(static_cast<std::size_t>(cellBody[above]),
                 submerges(c, above, a, 1, grid.face(a, i + (a == 0), j + (a == 1), k + (a == 2))));
          }
        }
      }
    }
  }
  combineBodies(wet, 2, true);
  // Every block rasterised every body that reaches its planes and the plane beyond them, so
  // each turns the same cells to air there.
  const std::size_t plane = static_cast<std::size_t>(grid.nx) * grid.ny;
  const std::size_t cFrom = plane * static_cast<std::size_t>(std::max(0, k0 - 1));
  const std::size_t cTo = plane * static_cast<std::size_t>(std::min(grid.nz, k1 + 1));
  for (std::size_t c = cFrom; c < cTo; ++c) {
    if (kind[c] == detail::kBody && wet[2 * static_cast<std::size_t>(cellBody[c])] == 0.0) {
      kind[c] = detail::kAir;
      cellDensity[c] = settings.density;
    }
  }
  inLiquid.assign(bodyCount, 0.0);
  for (std::size_t b = 0; b < bodyCount; ++b) inLiquid[b] = wet[2 * b + 1];
}

void FluidSolver::Impl::fillPlane(int a, int k, double* value, const unsigned char* ok,
                                  std::vector<std::size_t>& out) const {
  const int dx = grid.fdim(a, 0), dy = grid.fdim(a, 1), dz = grid.fdim(a, 2);
  const std::size_t sy = static_cast<std::size_t>(dx), sz = sy * static_cast<std::size_t>(dy);
  for (int j = 0; j < dy; ++j) {
    const std::size_t r = static_cast<std::size_t>(k) * dy + j;
    if (rowState[r] & 2) continue;  // nothing to fill
    const bool near = (rowState[r] & 1) || (j > 0 && (rowState[r - 1] & 1)) ||
                      (j + 1 < dy && (rowState[r + 1] & 1)) || (k > 0 && (rowState[r - dy] & 1)) ||
                      (k + 1 < dz && (rowState[r + dy] & 1));
    if (!near) continue;
    std::size_t f = grid.face(a, 0, j, k);
    for (int i = 0; i < dx; ++i, ++f) {
      if (ok[f]) continue;
      double total = 0.0;
      int count = 0;
      auto take = [&](std::size_t g) {
        if (ok[g]) {
          total += value[g];
          ++count;
        }
      };
      if (i > 0) take(f - 1);
      if (i + 1 < dx) take(f + 1);
      if (j > 0) take(f - sy);
      if (j + 1 < dy) take(f + sy);
      if (k > 0) take(f - sz);
      if (k + 1 < dz) take(f + sz);
      if (count > 0) {
        value[f] = total / count;
        out.push_back(f);
      }
    }
  }
}

void FluidSolver::Impl::extrapolate(std::vector<double>* field, int layers) {
  for (int a = 0; a < 3; ++a) {
    const int dx = grid.fdim(a, 0), dy = grid.fdim(a, 1), dz = grid.fdim(a, 2);
    const int ke = kEnd(a);
    for (int layer = 0; layer < layers; ++layer) {
      exchangeWithValidity(field[a], valid[a], a);
      double* value = field[a].data();
      unsigned char* ok = valid[a].data();
      const int kLo = std::max(0, k0 - 1), kHi = std::min(dz, ke + 1);
      rowState.assign(static_cast<std::size_t>(dy) * static_cast<std::size_t>(dz), 0);
      const int threads = settings.threads;
      workers->forRanges(
          threads, static_cast<std::size_t>(kHi - kLo),
          [&](std::size_t, std::size_t from, std::size_t to) {
            for (int k = kLo + static_cast<int>(from); k < kLo + static_cast<int>(to); ++k) {
              for (int j = 0; j < dy; ++j) {
                const unsigned char* row = ok + grid.face(a, 0, j, k);
                int count = 0;
                for (int i = 0; i < dx; ++i) count += row[i];
                rowState[static_cast<std::size_t>(k) * dy + j] =
                    static_cast<unsigned char>((count > 0 ? 1 : 0) | (count == dx ? 2 : 0));
              }
            }
          });
      // A face is filled from valid neighbours only, and becomes valid after the pass: the
      // planes are independent within a pass, so threads take runs of them, each listing what
      // it filled.
      filledPerThread.resize(static_cast<std::size_t>(threads));
      workers->forRanges(threads, static_cast<std::size_t>(ke - k0),
                         [&](std::size_t part, std::size_t from, std::size_t to) {
                           auto& mine = filledPerThread[part];
                           mine.clear();
                           for (int k = k0 + static_cast<int>(from); k < k0 + static_cast<int>(to);
                                ++k) {
                             fillPlane(a, k, value, ok, mine);
                           }
                         });
      filled.clear();
      for (const auto& part : filledPerThread)
        filled.insert(filled.end(), part.begin(), part.end());
      for (const std::size_t f : filled) ok[f] = 1;
    }
  }
}

void FluidSolver::Impl::enforceBodies(const std::vector<PreparedBody>& bodies, bool kinematicOnly) {
  const double o[3] = {grid.ox, grid.oy, grid.oz};
  for (int a = 0; a < 3; ++a) {
    // Each face row (j, k) is visited once, over the union of the bodies' ranges in it (their
    // bounds and one cell): a net's nodes overlap each other's ranges, and visiting each body's
    // own range visited most faces several times. A face is set to the velocity of the body it
    // belongs to, which always lies within that body's range.
    const int ny = grid.fdim(a, 1);
    const int planes = kEnd(a) - k0;
    if (planes <= 0) continue;
    auto& rowLo = enforceRowLo;
    auto& rowHi = enforceRowHi;
    rowLo.assign(static_cast<std::size_t>(planes) * ny, grid.fdim(a, 0));
    rowHi.assign(static_cast<std::size_t>(planes) * ny, -1);
    for (const auto& box : bodies) {
      if (kinematicOnly && !box.kinematic) continue;
      int lo[3], hi[3];
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::max(0, static_cast<int>(std::floor((box.bounds.min[d] - o[d]) * invH)) - 1);
        hi[d] = std::min(grid.fdim(a, d) - 1,
                         static_cast<int>(std::ceil((box.bounds.max[d] - o[d]) * invH)) + 1);
      }
      lo[2] = std::max(lo[2], k0);
      hi[2] = std::min(hi[2], kEnd(a) - 1);
      for (int k = lo[2]; k <= hi[2]; ++k) {
        for (int j = lo[1]; j <= hi[1]; ++j) {
          const std::size_t row = static_cast<std::size_t>(k - k0) * ny + j;
          rowLo[row] = std::min(rowLo[row], lo[0]);
          rowHi[row] = std::max(rowHi[row], hi[0]);
        }
      }
    }
    const std::size_t across = stride(a);
    for (int k = k0; k < kEnd(a); ++k) {
      for (int j = 0; j < ny; ++j) {
        const std::size_t row = static_cast<std::size_t>(k - k0) * ny + j;
        std::size_t f = grid.face(a, rowLo[row], j, k);
        for (int i = rowLo[row]; i <= rowHi[row]; ++i, ++f) {
          int b = faceBody[a][f];
          if (b < 0 && !onWall(a, i, j, k)) {  // the faces of a kinematic body's cells too
            const std::size_t hiCell = grid.cell(i, j, k), loCell = hiCell - across;
            if (kind[hiCell] == detail::kSolid) b = cellBody[hiCell];
            if (kind[loCell] == detail::kSolid) b = cellBody[loCell];
            // Between a body's cell and air the body's surface moves with the body: the
            // liquid's velocity extrapolated there (or zero) would make the body's cells
            // diverge, and the projection would brake the body as if air were liquid.
            if (b < 0 && kind[hiCell] == detail::kBody && kind[loCell] == detail::kAir) {
              b = cellBody[hiCell];
            }
            if (b < 0 && kind[loCell] == detail::kBody && kind[hiCell] == detail::kAir) {
              b = cellBody[loCell];
            }
          }
          if (b < 0) continue;
          const auto& box = bodies[static_cast<std::size_t>(b)];
          if (kinematicOnly && !box.kinematic) continue;
          u[a][f] =
              detail::rigidVelocity(box, facePosition(a, i, j, k))[static_cast<std::size_t>(a)];
        }
      }
    }
  }
}

}  // namespace vrflow::fluid
