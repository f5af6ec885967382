#include "vrflow/fluid/solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "bodies.hpp"
#include "grid.hpp"
#include "pressure.hpp"
#include "transfer.hpp"
#include "vrflow/fluid/block_comm.hpp"

namespace vrflow::fluid {

using detail::Grid;
using detail::PreparedBody;

namespace {
constexpr int kHaloForParticles = 3;  // planes of velocity a block's particles may sample
constexpr int kParticleRecord = 6;    // position and velocity
constexpr double kMinTheta = 0.2;     // keeps ghost-fluid coefficients (1 / theta) bounded
}  // namespace

struct FluidSolver::Impl {
  FluidSettings settings;
  Grid grid;
  double invH = 1.0;
  int k0 = 0, k1 = 0;       // this block's cell planes
  std::vector<double> pos;  // xyz per particle (this block's)
  std::vector<double> vel;
  std::vector<float> posOut;
  std::vector<double> u[3], uOld[3];
  std::vector<double> acc[3];  // particle-to-grid sums: (weighted velocity, weight) per face
  std::vector<unsigned char> valid[3];
  std::vector<int> faceBody[3];
  std::vector<int> cellBody;
  std::vector<unsigned char> kind;
  std::vector<double> cellDensity;
  std::vector<int> particlesInCell;
  std::vector<double> divTarget;  // per cell, times 1/dt
  // Free surface (ghost fluid): distance, in cells, from an unknown cell's centre to where
  // p = 0 lies towards an air neighbour. A liquid cell's particle count says how full it is:
  // full puts the surface at the face (0.5); a body cell's surface is taken at its face (0.5).
  std::vector<double> theta;
  detail::PressureSystem system;
  detail::PcgWorkspace pcg;
  std::vector<double> rhs, pressure;
  StepStats stats;
  double maxDiv = 0.0;
  double lastDt = 1.0;
  BlockComm* comm = nullptr;
  std::uint64_t rng = 1;

  double nextJitter() {  // splitmix64 -> [-0.5, 0.5)
    std::uint64_t z = (rng += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53 - 0.5;
  }

  // This block's face planes of component a: [k0, kEnd(a)); the top wall's w plane goes to the
  // last block.
  int kEnd(int a) const { return (a == 2 && k1 == grid.nz) ? grid.nz + 1 : k1; }
  int planeSize(int a) const { return grid.fdim(a, 0) * grid.fdim(a, 1); }

  void exchange(std::vector<double>& field, int a, int depth) {
    if (comm) comm->exchangeHalo(field, planeSize(a), grid.fdim(a, 2), k0, k1, depth);
  }
  void exchangeCells(std::vector<double>& field) {
    if (comm) comm->exchangeHalo(field, grid.nx * grid.ny, grid.nz, k0, k1, 1);
  }
  // Byte fields travel as doubles; only the planes sent (k0, k1 - 1) and received (k0 - 1, k1)
  // are converted, in a scratch field kept between calls.
  std::vector<double> byteScratch;
  void exchangeBytes(std::vector<unsigned char>& bytes, int planeSizeBytes, int planes) {
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
  // A face field and its validity flags in one halo exchange (depth 1): both travel as
  // (value, flag) pairs; only the planes sent and received are packed.
  std::vector<double> haloScratch;
  void exchangeWithValidity(std::vector<double>& field, std::vector<unsigned char>& flags, int a) {
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
  double sum(double v) { return comm ? comm->sum(v) : v; }
  double max(double v) { return comm ? comm->max(v) : v; }

  msg::Vec3 facePosition(int a, int i, int j, int k) const {
    const double h = grid.h;
    msg::Vec3 x{grid.ox + (i + 0.5) * h, grid.oy + (j + 0.5) * h, grid.oz + (k + 0.5) * h};
    x[static_cast<std::size_t>(a)] -= 0.5 * h;
    return x;
  }

  void clampToDomain(double* x) const {
    const double eps = 1e-3 * grid.h;
    const double lo[3] = {grid.ox, grid.oy, grid.oz};
    const int n[3] = {grid.nx, grid.ny, grid.nz};
    for (int d = 0; d < 3; ++d) x[d] = std::clamp(x[d], lo[d] + eps, lo[d] + n[d] * grid.h - eps);
  }

  bool cellOf(const double* x, int& i, int& j, int& k) const {
    i = static_cast<int>(std::floor((x[0] - grid.ox) * invH));
    j = static_cast<int>(std::floor((x[1] - grid.oy) * invH));
    k = static_cast<int>(std::floor((x[2] - grid.oz) * invH));
    return i >= 0 && j >= 0 && k >= 0 && i < grid.nx && j < grid.ny && k < grid.nz;
  }

  int planeOf(const double* x) const {
    const int k = static_cast<int>(std::floor((x[2] - grid.oz) * invH));
    return std::clamp(k, 0, grid.nz - 1);
  }

  // Loops over this block's faces of component a (with the along-axis index).
  template <typename F>
  void forOwnFaces(int a, F&& f) const {
    const int ke = kEnd(a);
    for (int k = k0; k < ke; ++k) {
      for (int j = 0; j < grid.fdim(a, 1); ++j) {
        std::size_t idx = grid.face(a, 0, j, k);
        for (int i = 0; i < grid.fdim(a, 0); ++i, ++idx) f(idx, i, j, k);
      }
    }
  }

  // Per cell row (j, k) of this block's planes and one beyond: whether it holds a cell that is
  // not air (set by classify()). Faces next to air only are skipped by forFacesNearMatter().
  std::vector<unsigned char> rowHasMatter;
  void markRowsWithMatter() {
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
  // forOwnFaces() restricted to the rows of faces with a cell that is not air on either side.
  template <typename F>
  void forFacesNearMatter(int a, F&& f) const {
    const int ke = kEnd(a);
    const int ny = grid.ny, nz = grid.nz;
    auto busy = [&](int j, int k) {
      return j >= 0 && j < ny && k >= 0 && k < nz &&
             rowHasMatter[static_cast<std::size_t>(k) * ny + j];
    };
    for (int k = k0; k < ke; ++k) {
      for (int j = 0; j < grid.fdim(a, 1); ++j) {
        const bool near = busy(j, k) || (a == 1 && busy(j - 1, k)) || (a == 2 && busy(j, k - 1));
        if (!near) continue;
        std::size_t idx = grid.face(a, 0, j, k);
        for (int i = 0; i < grid.fdim(a, 0); ++i, ++idx) f(idx, i, j, k);
      }
    }
  }

  bool onWall(int a, int i, int j, int k) const {
    const int along = a == 0 ? i : a == 1 ? j : k;
    return along == 0 || along == grid.fdim(a, a) - 1;
  }

  void zeroWalls(std::vector<double>* field) const {
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

  // Moves particles that left this block's slab to the block that owns them now.
  void migrate() {
    if (!comm) return;
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

  // The cell of each particle (clamped into the grid), in particle order. The advection stores
  // it when particles do not change blocks afterwards (serial or one block), so that pushing
  // out of bodies and sorting need not locate every particle again; `cellsKnown` says so.
  std::vector<std::uint32_t> sortCell;
  bool cellsKnown = false;
  std::uint32_t clampedCell(const double* x) const {
    int i, j, k;
    cellOf(x, i, j, k);
    i = std::clamp(i, 0, grid.nx - 1);
    j = std::clamp(j, 0, grid.ny - 1);
    k = std::clamp(k, 0, grid.nz - 1);
    return static_cast<std::uint32_t>(grid.cell(i, j, k));
  }
  std::vector<std::size_t> sortStart;
  std::vector<double> posScratch, velScratch;
  // Stable counting sort of the particles by cell (memory order), for cache-friendly transfers
  // and an order that does not depend on history.
  void sortParticles() {
    // This block's particles all lie in its slab (cellOf clamps as planeOf does in migrate), so
    // only the slab's cells are counted; the others keep their zero counts.
    const std::size_t n = pos.size() / 3;
    const std::size_t plane = static_cast<std::size_t>(grid.nx) * grid.ny;
    const std::size_t c0 = plane * static_cast<std::size_t>(k0),
                      c1 = plane * static_cast<std::size_t>(k1);
    std::fill(particlesInCell.begin() + static_cast<std::ptrdiff_t>(c0),
              particlesInCell.begin() + static_cast<std::ptrdiff_t>(c1), 0);
    if (!cellsKnown) {
      sortCell.resize(n);
      for (std::size_t p = 0; p < n; ++p) sortCell[p] = clampedCell(&pos[3 * p]);
    }
    for (std::size_t p = 0; p < n; ++p) ++particlesInCell[sortCell[p]];
    sortStart.resize(grid.cells() + 1);
    sortStart[c0] = 0;
    for (std::size_t c = c0; c < c1; ++c) {
      sortStart[c + 1] = sortStart[c] + static_cast<std::size_t>(particlesInCell[c]);
    }
    posScratch.resize(pos.size());
    velScratch.resize(vel.size());
    for (std::size_t p = 0; p < n; ++p) {
      const std::size_t to = sortStart[sortCell[p]]++;
      for (int d = 0; d < 3; ++d) {
        posScratch[3 * to + d] = pos[3 * p + d];
        velScratch[3 * to + d] = vel[3 * p + d];
      }
    }
    pos.swap(posScratch);
    vel.swap(velScratch);
    cellsKnown = false;
  }

  // Only particles in cells that some body's bounds touch are tested against the bodies.
  std::vector<unsigned char> nearBody;
  void pushParticlesOut(const std::vector<PreparedBody>& bodies) {
    if (bodies.empty()) return;
    nearBody.assign(grid.cells(), 0);
    const double o[3] = {grid.ox, grid.oy, grid.oz};
    const int n[3] = {grid.nx, grid.ny, grid.nz};
    for (const auto& body : bodies) {
      int lo[3], hi[3];
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::max(0, static_cast<int>(std::floor((body.bounds.min[d] - o[d]) * invH)) - 1);
        hi[d] = std::min(n[d] - 1,
                         static_cast<int>(std::floor((body.bounds.max[d] - o[d]) * invH)) + 1);
      }
      for (int k = lo[2]; k <= hi[2]; ++k) {
        for (int j = lo[1]; j <= hi[1]; ++j) {
          for (int i = lo[0]; i <= hi[0]; ++i) nearBody[grid.cell(i, j, k)] = 1;
        }
      }
    }
    const std::size_t count = pos.size() / 3;
    for (std::size_t p = 0; p < count; ++p) {
      double* x = &pos[3 * p];
      if (cellsKnown) {
        if (!nearBody[sortCell[p]]) continue;
      } else {
        int i, j, k;
        if (!cellOf(x, i, j, k) || !nearBody[grid.cell(i, j, k)]) continue;
      }
      for (const auto& body : bodies) {
        if (!detail::inBounds(body.bounds, x)) continue;
        detail::pushOut(body, x, 0.25 * grid.h);
        clampToDomain(x);
      }
      if (cellsKnown) sortCell[p] = clampedCell(x);
    }
  }

  void classify(const std::vector<PreparedBody>& bodies) {
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

  void particlesToGrid() {
    // This block's particles reach face planes k0 - 1 to k1.
    for (int a = 0; a < 3; ++a) {
      const std::size_t ps = 2 * static_cast<std::size_t>(planeSize(a));
      const auto from =
          static_cast<std::ptrdiff_t>(ps * static_cast<std::size_t>(std::max(0, k0 - 1)));
      const auto to = static_cast<std::ptrdiff_t>(
          ps * static_cast<std::size_t>(std::min(grid.fdim(a, 2), k1 + 1)));
      std::fill(acc[a].begin() + from, acc[a].begin() + to, 0.0);
    }
    const detail::Lattice lattice(grid);
    double* sums[3] = {acc[0].data(), acc[1].data(), acc[2].data()};
    const std::size_t n = pos.size() / 3;
    const double* x = pos.data();
    const double* v = vel.data();
    for (std::size_t p = 0; p < n; ++p, x += 3, v += 3) {
      detail::Located c;
      detail::locate(lattice, x, c);
      detail::splat(sums[0], detail::stencilOf(lattice, 0, c), v[0]);
      detail::splat(sums[1], detail::stencilOf(lattice, 1, c), v[1]);
      detail::splat(sums[2], detail::stencilOf(lattice, 2, c), v[2]);
    }
    for (int a = 0; a < 3; ++a) {
      if (comm) comm->addHalo(acc[a], 2 * planeSize(a), grid.fdim(a, 2), k0, k1);
      // Faces of other blocks read zero (this block's are all written below).
      const auto ps = static_cast<std::ptrdiff_t>(planeSize(a));
      std::fill(u[a].begin(), u[a].begin() + ps * k0, 0.0);
      std::fill(u[a].begin() + ps * kEnd(a), u[a].end(), 0.0);
      const double* in = acc[a].data();
      forOwnFaces(a, [&](std::size_t f, int, int, int) {
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

  // Fills faces without a value from the mean of valid neighbours, `layers` rings deep. Only
  // rows (j, k) with a valid face in them or next to them can gain values; the others (deep in
  // air) are skipped.
  std::vector<unsigned char> rowState;  // per row: bit 0 some face valid, bit 1 every face valid
  std::vector<std::size_t> filled;
  void extrapolate(std::vector<double>* field, int layers) {
    for (int a = 0; a < 3; ++a) {
      const int dx = grid.fdim(a, 0), dy = grid.fdim(a, 1), dz = grid.fdim(a, 2);
      const std::size_t sy = static_cast<std::size_t>(dx), sz = sy * static_cast<std::size_t>(dy);
      const int ke = kEnd(a);
      for (int layer = 0; layer < layers; ++layer) {
        exchangeWithValidity(field[a], valid[a], a);
        double* value = field[a].data();
        unsigned char* ok = valid[a].data();
        const int kLo = std::max(0, k0 - 1), kHi = std::min(dz, ke + 1);
        rowState.assign(static_cast<std::size_t>(dy) * static_cast<std::size_t>(dz), 0);
        for (int k = kLo; k < kHi; ++k) {
          for (int j = 0; j < dy; ++j) {
            const unsigned char* row = ok + grid.face(a, 0, j, k);
            int count = 0;
            for (int i = 0; i < dx; ++i) count += row[i];
            rowState[static_cast<std::size_t>(k) * dy + j] =
                static_cast<unsigned char>((count > 0 ? 1 : 0) | (count == dx ? 2 : 0));
          }
        }
        filled.clear();
        for (int k = k0; k < ke; ++k) {
          for (int j = 0; j < dy; ++j) {
            const std::size_t r = static_cast<std::size_t>(k) * dy + j;
            if (rowState[r] & 2) continue;  // nothing to fill
            const bool near = (rowState[r] & 1) || (j > 0 && (rowState[r - 1] & 1)) ||
                              (j + 1 < dy && (rowState[r + 1] & 1)) ||
                              (k > 0 && (rowState[r - dy] & 1)) ||
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
                filled.push_back(f);
              }
            }
          }
        }
        for (const std::size_t f : filled) ok[f] = 1;
      }
    }
  }

  // Rigid motion on the faces of bodies (and of kinematic bodies' cells); `kinematicOnly`
  // re-imposes it on kinematic bodies after gravity (a moving wall does not fall). Only the
  // faces in each body's bounds (one cell wider) can be affected; a face in several bodies'
  // bounds gets the same value each time.
  void enforceBodies(const std::vector<PreparedBody>& bodies, bool kinematicOnly = false) {
    const double o[3] = {grid.ox, grid.oy, grid.oz};
    for (const auto& box : bodies) {
      if (kinematicOnly && !box.kinematic) continue;
      for (int a = 0; a < 3; ++a) {
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
            for (int i = lo[0]; i <= hi[0]; ++i) {
              const std::size_t f = grid.face(a, i, j, k);
              int b = faceBody[a][f];
              if (b < 0 && !onWall(a, i, j, k)) {  // the faces of a kinematic body's cells too
                const std::size_t hiCell = grid.cell(i, j, k), loCell = hiCell - stride(a);
                if (kind[hiCell] == detail::kSolid) b = cellBody[hiCell];
                if (kind[loCell] == detail::kSolid) b = cellBody[loCell];
              }
              if (b < 0) continue;
              const auto& body = bodies[static_cast<std::size_t>(b)];
              if (kinematicOnly && !body.kinematic) continue;
              u[a][f] = detail::rigidVelocity(
                  body, facePosition(a, i, j, k))[static_cast<std::size_t>(a)];
            }
          }
        }
      }
    }
  }

  bool unknown(std::size_t c) const {
    return kind[c] == detail::kLiquid || kind[c] == detail::kBody;
  }
  bool solid(std::size_t c) const { return kind[c] == detail::kSolid; }

  std::size_t stride(int a) const {
    return a == 0   ? 1
           : a == 1 ? static_cast<std::size_t>(grid.nx)
                    : static_cast<std::size_t>(grid.nx) * grid.ny;
  }

  // Pressure projection with variable density (bodies carry their own) and p = 0 in air.
  void project(double dt) {
    const std::size_t n = grid.cells();
    auto& A = system;
    // The system is built on this block's cells and read one plane beyond them.
    const std::size_t plane = static_cast<std::size_t>(grid.nx) * grid.ny;
    const auto cFrom =
        static_cast<std::ptrdiff_t>(plane * static_cast<std::size_t>(std::max(0, k0 - 1)));
    const auto cTo =
        static_cast<std::ptrdiff_t>(plane * static_cast<std::size_t>(std::min(grid.nz, k1 + 1)));
    for (auto* v : {&A.diag, &A.ax, &A.ay, &A.az, &rhs}) {
      v->resize(n);
      std::fill(v->begin() + cFrom, v->begin() + cTo, 0.0);
    }
    const double h = grid.h;
    lastDt = dt;
    stats.targetDivergence = -settings.volumeCorrection * (1.0 - stats.particleDensity) / dt;
    exchange(u[2], 2, 1);  // the w faces above this block's top plane
    const int dims[3] = {grid.nx, grid.ny, grid.nz};
    for (int k = k0; k < k1; ++k) {
      for (int j = 0; j < grid.ny; ++j) {
        for (int i = 0; i < grid.nx; ++i) {
          const std::size_t c = grid.cell(i, j, k);
          if (!unknown(c)) continue;
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
              A.diag[c] += unknown(nbr) ? beta : beta / theta[c];
              if (side > 0 && unknown(nbr)) (a == 0 ? A.ax : a == 1 ? A.ay : A.az)[c] = -beta;
            }
          }
        }
      }
    }
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
      forFacesNearMatter(a, [&](std::size_t f, int i, int j, int k) {
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

  void measureDivergence() {
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

  void markProjectedFaces() {
    for (int a = 0; a < 3; ++a) {
      const auto ps = static_cast<std::ptrdiff_t>(planeSize(a));
      std::fill(valid[a].begin() + ps * k0, valid[a].begin() + ps * kEnd(a), 0);
      forFacesNearMatter(a, [&](std::size_t f, int i, int j, int k) {
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

  void gridToParticlesAndAdvect(double dt) {
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
    const std::size_t n = pos.size() / 3;
    const bool storeCells = !comm || comm->size() == 1;
    if (storeCells) sortCell.resize(n);
    // Two passes (velocities and midpoints, then positions) rather than one: within a particle
    // the second interpolation waits for the first, and a pass of short independent chains
    // keeps more particles in flight.
    posScratch.resize(pos.size());
    double* midpoints = posScratch.data();
    for (std::size_t p = 0; p < n; ++p) {
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
    for (std::size_t p = 0; p < n; ++p) {
      double* x = &pos[3 * p];
      detail::Located c;
      detail::locate(lattice, midpoints + 3 * p, c);
      x[0] += dt * detail::gatherPair(pairs[0], detail::stencilOf(lattice, 0, c))[0];
      x[1] += dt * detail::gatherPair(pairs[1], detail::stencilOf(lattice, 1, c))[0];
      x[2] += dt * detail::gatherPair(pairs[2], detail::stencilOf(lattice, 2, c))[0];
      clamp(x);
      if (storeCells) sortCell[p] = clampedCell(x);
    }
    cellsKnown = storeCells;
  }

  void refreshOutput() {
    posOut.resize(pos.size());
    for (std::size_t q = 0; q < pos.size(); ++q) posOut[q] = static_cast<float>(pos[q]);
  }
};

FluidSolver::FluidSolver(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
FluidSolver::~FluidSolver() = default;

Result<std::unique_ptr<FluidSolver>> FluidSolver::create(const FluidSettings& settings) {
  if (auto status = validateSettings(settings); !status) return status.error();
  auto impl = std::make_unique<Impl>();
  impl->settings = settings;
  impl->rng = settings.seed;
  auto& g = impl->grid;
  g.nx = settings.nx;
  g.ny = settings.ny;
  g.nz = settings.nz;
  g.h = settings.cellSize;
  g.ox = settings.origin[0];
  g.oy = settings.origin[1];
  g.oz = settings.origin[2];
  impl->invH = 1.0 / g.h;
  impl->k0 = 0;
  impl->k1 = g.nz;
  for (int a = 0; a < 3; ++a) {
    impl->u[a].assign(g.faces(a), 0.0);
    impl->uOld[a].assign(g.faces(a), 0.0);
    impl->acc[a].assign(2 * g.faces(a), 0.0);
    impl->valid[a].assign(g.faces(a), 0);
    impl->faceBody[a].assign(g.faces(a), -1);
  }
  impl->cellBody.assign(g.cells(), -1);
  impl->kind.assign(g.cells(), detail::kAir);
  impl->cellDensity.assign(g.cells(), settings.density);
  impl->pressure.assign(g.cells(), 0.0);
  impl->particlesInCell.assign(g.cells(), 0);
  impl->divTarget.assign(g.cells(), 0.0);
  return std::unique_ptr<FluidSolver>(new FluidSolver(std::move(impl)));
}

Status FluidSolver::setBlockComm(BlockComm* comm) {
  auto& m = *impl_;
  if (!m.pos.empty()) return makeError("fluid: set the block link before adding liquid");
  if (comm && (comm->size() < 1 || comm->size() > m.grid.nz)) {
    return makeError("fluid: " + std::to_string(comm ? comm->size() : 0) +
                     " blocks for a grid of " + std::to_string(m.grid.nz) +
                     " z-planes: each block needs at least one plane");
  }
  m.comm = comm;
  if (comm) {
    slabOf(m.grid.nz, comm->rank(), comm->size(), m.k0, m.k1);
  } else {
    m.k0 = 0;
    m.k1 = m.grid.nz;
  }
  return {};
}

Status FluidSolver::addLiquidBox(const msg::Aabb& box) {
  auto& m = *impl_;
  for (int d = 0; d < 3; ++d) {
    if (!std::isfinite(box.min[d]) || !std::isfinite(box.max[d]) || box.max[d] <= box.min[d]) {
      return makeError("fluid: liquid box must be finite with max > min on every axis");
    }
  }
  const auto& g = m.grid;
  const int per = m.settings.particlesPerCell == 27 ? 3 : m.settings.particlesPerCell == 8 ? 2 : 1;
  std::vector<std::size_t> seeded;
  for (int k = 0; k < g.nz; ++k) {
    for (int j = 0; j < g.ny; ++j) {
      for (int i = 0; i < g.nx; ++i) {
        const double c[3] = {g.ox + (i + 0.5) * g.h, g.oy + (j + 0.5) * g.h,
                             g.oz + (k + 0.5) * g.h};
        bool inside = true;
        for (int d = 0; d < 3; ++d) inside = inside && c[d] >= box.min[d] && c[d] <= box.max[d];
        if (inside) seeded.push_back(g.cell(i, j, k));
      }
    }
  }
  // Every block draws the same jitter sequence and keeps the particles in its slab, so the
  // particles are those of the serial run.
  const std::size_t existing =
      static_cast<std::size_t>(m.sum(static_cast<double>(m.pos.size() / 3)));
  const std::size_t total = existing + seeded.size() * static_cast<std::size_t>(per * per * per);
  if (total > static_cast<std::size_t>(m.settings.maxParticles)) {
    return makeError("fluid: the liquid box needs " + std::to_string(total) +
                     " particles, more than the limit of " +
                     std::to_string(m.settings.maxParticles));
  }
  if (seeded.empty()) return makeError("fluid: the liquid box holds no cell centre of the grid");
  const std::size_t nx = static_cast<std::size_t>(g.nx), ny = static_cast<std::size_t>(g.ny);
  for (const std::size_t c : seeded) {
    const int idx[3] = {static_cast<int>(c % nx), static_cast<int>((c / nx) % ny),
                        static_cast<int>(c / (nx * ny))};
    const bool mine = idx[2] >= m.k0 && idx[2] < m.k1;
    const double o[3] = {g.ox, g.oy, g.oz};
    for (int sk = 0; sk < per; ++sk) {
      for (int sj = 0; sj < per; ++sj) {
        for (int si = 0; si < per; ++si) {
          const int s[3] = {si, sj, sk};
          double x[3];
          for (int d = 0; d < 3; ++d) {
            const double sub = (s[d] + 0.5 + 0.5 * m.nextJitter()) / per;
            x[d] = o[d] + (idx[d] + sub) * g.h;
          }
          if (!mine) continue;
          m.pos.insert(m.pos.end(), x, x + 3);
          m.cellsKnown = false;
          m.vel.insert(m.vel.end(), 3, 0.0);
        }
      }
    }
  }
  m.refreshOutput();
  return {};
}

Result<std::vector<BodyForce>> FluidSolver::step(double dt, const std::vector<RigidBody>& bodies,
                                                 const std::vector<PointMass>& points) {
  auto& m = *impl_;
  if (auto status = validateTimeStep(m.settings, dt); !status) return status.error();
  std::vector<PreparedBody> prepared;
  prepared.reserve(bodies.size() + points.size());
  for (const auto& body : bodies) {
    auto p = detail::prepareBody(body, m.settings.density);
    if (!p) return p.error();
    prepared.push_back(std::move(*p));
  }
  for (const auto& point : points) {
    auto p = detail::preparePoint(point);
    if (!p) return p.error();
    prepared.push_back(std::move(*p));
  }

  m.pushParticlesOut(prepared);
  m.migrate();
  m.sortParticles();
  m.classify(prepared);
  m.particlesToGrid();
  m.extrapolate(m.u, 2);
  m.enforceBodies(prepared);
  m.zeroWalls(m.u);
  for (int a = 0; a < 3; ++a) {
    const double dv = m.settings.gravity[static_cast<std::size_t>(a)] * dt;
    m.forOwnFaces(a, [&](std::size_t f, int, int, int) {
      m.uOld[a][f] = m.u[a][f];
      m.u[a][f] += dv;
    });
  }
  m.enforceBodies(prepared, true);
  m.zeroWalls(m.u);
  m.project(dt);
  m.measureDivergence();

  std::vector<double> sums(prepared.size() * detail::kBodySums, 0.0);
  const int kEnd[3] = {m.kEnd(0), m.kEnd(1), m.kEnd(2)};
  for (std::size_t b = 0; b < prepared.size(); ++b) {
    detail::bodyForceSums(m.grid, prepared[b], static_cast<int>(b), m.faceBody, m.u, m.uOld,
                          m.settings.gravity, dt, m.k0, kEnd, &sums[b * detail::kBodySums]);
  }
  if (m.comm && !sums.empty()) m.comm->sum(sums);
  std::vector<BodyForce> forces;
  forces.reserve(prepared.size());
  for (std::size_t b = 0; b < prepared.size(); ++b) {
    forces.push_back(detail::finishBodyForce(prepared[b], &sums[b * detail::kBodySums], dt));
  }

  // Faces touching no liquid or body cell kept the pre-projection value; give them the
  // projected neighbours' instead so particles near the surface see the new field.
  m.markProjectedFaces();
  m.extrapolate(m.u, 2);
  m.zeroWalls(m.u);
  m.gridToParticlesAndAdvect(dt);
  m.migrate();
  m.refreshOutput();
  return forces;
}

const FluidSettings& FluidSolver::settings() const {
  return impl_->settings;
}
const StepStats& FluidSolver::lastStats() const {
  return impl_->stats;
}
const std::vector<float>& FluidSolver::particlePositions() const {
  return impl_->posOut;
}

std::vector<float> FluidSolver::gatherParticlePositions() const {
  return impl_->comm ? impl_->comm->gatherToRoot(impl_->posOut) : impl_->posOut;
}

std::size_t FluidSolver::particleCount() const {
  return static_cast<std::size_t>(impl_->sum(static_cast<double>(impl_->pos.size() / 3)));
}

double FluidSolver::liquidVolume() const {
  // Particle-estimated: particles / (particlesPerCell x the mean particles per cell of interior
  // liquid cells, relative) cells. Particles that clump (denser interior) read as lost volume,
  // particles that drift apart as gained volume; splashes and surface cells do not bias it.
  auto& m = *impl_;
  const double particles = m.sum(static_cast<double>(m.pos.size() / 3));
  const double density = m.stats.particleDensity > 0.0 ? m.stats.particleDensity : 1.0;
  return particles / (m.settings.particlesPerCell * density) * m.grid.h * m.grid.h * m.grid.h;
}

double FluidSolver::maxParticleSpeed() const {
  auto& m = *impl_;
  double best = 0.0;
  for (std::size_t p = 0; p + 2 < m.vel.size(); p += 3) {
    best = std::max(best, std::sqrt(m.vel[p] * m.vel[p] + m.vel[p + 1] * m.vel[p + 1] +
                                    m.vel[p + 2] * m.vel[p + 2]));
  }
  return m.max(best);
}

double FluidSolver::surfaceHeightAt(double x, double z) const {
  auto& m = *impl_;
  const int ci = static_cast<int>(std::floor((x - m.grid.ox) * m.invH));
  const int ck = static_cast<int>(std::floor((z - m.grid.oz) * m.invH));
  double top = m.grid.oy;
  for (std::size_t p = 0; p + 2 < m.pos.size(); p += 3) {
    const int i = static_cast<int>(std::floor((m.pos[p] - m.grid.ox) * m.invH));
    const int k = static_cast<int>(std::floor((m.pos[p + 2] - m.grid.oz) * m.invH));
    if (i == ci && k == ck) top = std::max(top, m.pos[p + 1]);
  }
  return m.max(top);
}

double FluidSolver::maxDivergence() const {
  return impl_->maxDiv;
}

msg::Aabb FluidSolver::bounds() const {
  const auto& g = impl_->grid;
  return {{g.ox, g.oy, g.oz}, {g.ox + g.nx * g.h, g.oy + g.ny * g.h, g.oz + g.nz * g.h}};
}

}  // namespace vrflow::fluid
