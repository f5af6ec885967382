#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "bodies.hpp"
#include "grid.hpp"
#include "parallel.hpp"
#include "pressure.hpp"
#include "vrflow/fluid/block_comm.hpp"
#include "vrflow/fluid/solver.hpp"

// The solver's state and the passes of a step, shared by the files that implement them:
// solver.cpp (the public calls and the order of a step), particles.cpp (seeding aside, what
// particles do: migration, sorting, pushing out of bodies, and both transfers with the grid),
// cells.cpp (classifying cells, extrapolation, body velocities, walls, halo packing) and
// projection.cpp (the pressure projection and what is measured after it).

namespace vrflow::fluid {

using detail::Grid;
using detail::PreparedBody;

struct FluidSolver::Impl {
  FluidSettings settings;
  std::unique_ptr<detail::Workers> workers;  ///< settings.threads threads
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
  // Blocks holding their own body lists (setLocalBodies): the union of every block's bodies
  // (and, apart, of its nets' nodes), keyed (id, index) in order, the lowest block holding each,
  // and where each body of this block's list sits in the union.
  bool localBodies = false;
  struct BodyUnion {
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keys;
    std::vector<int> holder;
    std::vector<std::size_t> ofBody;
  };
  BodyUnion bodyUnion, nodeUnion;
  using BodyKeys = std::vector<std::pair<std::uint64_t, std::uint32_t>>;
  void uniteBodies(const BodyKeys& keys, BodyUnion& out);
  // Per-body values (`width` per body, in the order of this block's list) combined over every
  // block: summed, or the maximum taken. Collective whenever there is a block link.
  std::vector<double> unionScratch;
  void combineBodies(std::vector<double>& values, std::size_t width, bool maximum) {
    combineOver(bodyUnion, values, width, maximum);
  }
  void combineOver(const BodyUnion& over, std::vector<double>& values, std::size_t width,
                   bool maximum);
  // Whether this block reports body b of the union `over` (the lowest block holding it).
  bool reports(const BodyUnion& over, std::size_t b) const {
    return !(localBodies && comm) || over.holder[over.ofBody[b]] == comm->rank();
  }
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
  void exchangeBytes(std::vector<unsigned char>& bytes, int planeSizeBytes, int planes);
  // A face field and its validity flags in one halo exchange (depth 1): both travel as
  // (value, flag) pairs; only the planes sent and received are packed.
  std::vector<double> haloScratch;
  void exchangeWithValidity(std::vector<double>& field, std::vector<unsigned char>& flags, int a);
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

  // The index along one axis of the cell holding coordinate g (in cells), clamped into [0, n):
  // the same as clamping floor(g), without the floor (truncation after max(g, 0) is floor).
  static int clampedIndex(double g, int n) {
    const int i = static_cast<int>(std::max(g, 0.0));
    return i < n ? i : n - 1;
  }

  int planeOf(const double* x) const { return clampedIndex((x[2] - grid.oz) * invH, grid.nz); }

  // Loops over this block's faces of component a (with the along-axis index).
  template <typename F>
  void forOwnFaces(int a, F&& f) const {
    for (int k = k0; k < kEnd(a); ++k) forOwnFacesInPlane(a, k, f);
  }
  // The same among the solver's threads (a face written from its own values only).
  template <typename F>
  void forOwnFacesThreaded(int a, F&& f) const {
    forPlanes(k0, kEnd(a), [&](int k) { forOwnFacesInPlane(a, k, f); });
  }
  template <typename F>
  void forOwnFacesInPlane(int a, int k, F&& f) const {
    for (int j = 0; j < grid.fdim(a, 1); ++j) {
      std::size_t idx = grid.face(a, 0, j, k);
      for (int i = 0; i < grid.fdim(a, 0); ++i, ++idx) f(idx, i, j, k);
    }
  }

  // Per cell row (j, k) of this block's planes and one beyond: whether it holds a cell that is
  // not air (set by classify()). Faces next to air only are skipped by forFacesNearMatter().
  std::vector<unsigned char> rowHasMatter;
  void markRowsWithMatter();
  // forOwnFaces() restricted to the rows of faces with a cell that is not air on either side.
  template <typename F>
  void forFacesNearMatter(int a, F&& f) const {
    for (int k = k0; k < kEnd(a); ++k) forFacesNearMatterInPlane(a, k, f);
  }
  // The same, the planes cut into runs among the solver's threads: for passes that write each
  // face from values no other face of the pass writes.
  template <typename F>
  void forFacesNearMatterThreaded(int a, F&& f) const {
    forPlanes(k0, kEnd(a), [&](int k) { forFacesNearMatterInPlane(a, k, f); });
  }
  template <typename F>
  void forFacesNearMatterInPlane(int a, int k, F&& f) const {
    const int ny = grid.ny, nz = grid.nz;
    auto busy = [&](int j, int kk) {
      return j >= 0 && j < ny && kk >= 0 && kk < nz &&
             rowHasMatter[static_cast<std::size_t>(kk) * ny + j];
    };
    for (int j = 0; j < grid.fdim(a, 1); ++j) {
      const bool near = busy(j, k) || (a == 1 && busy(j - 1, k)) || (a == 2 && busy(j, k - 1));
      if (!near) continue;
      std::size_t idx = grid.face(a, 0, j, k);
      for (int i = 0; i < grid.fdim(a, 0); ++i, ++idx) f(idx, i, j, k);
    }
  }
  // Calls f(k) for the planes [from, to), cut into one run per thread.
  template <typename F>
  void forPlanes(int from, int to, F&& f) const {
    if (to <= from) return;
    workers->forRanges(workers->threads(), static_cast<std::size_t>(to - from),
                       [&](std::size_t, std::size_t b, std::size_t e) {
                         for (auto k = b; k < e; ++k) f(from + static_cast<int>(k));
                       });
  }

  bool onWall(int a, int i, int j, int k) const {
    const int along = a == 0 ? i : a == 1 ? j : k;
    return along == 0 || along == grid.fdim(a, a) - 1;
  }

  void zeroWalls(std::vector<double>* field) const;

  // Moves particles that left this block's slab to the block that owns them now.
  void migrate();

  // The cell of each particle (clamped into the grid), in particle order. The advection stores
  // it when particles do not change blocks afterwards (serial or one block), so that pushing
  // out of bodies and sorting need not locate every particle again; `cellsKnown` says so.
  std::vector<std::uint32_t> sortCell;
  bool cellsKnown = false;
  std::uint32_t clampedCell(const double* x) const {
    const int i = clampedIndex((x[0] - grid.ox) * invH, grid.nx);
    const int j = clampedIndex((x[1] - grid.oy) * invH, grid.ny);
    const int k = clampedIndex((x[2] - grid.oz) * invH, grid.nz);
    return static_cast<std::uint32_t>(grid.cell(i, j, k));
  }
  std::vector<std::size_t> sortStart;
  std::vector<std::size_t> planeStart;  ///< after sorting: first particle of each plane k0..k1
  std::vector<double> posScratch, velScratch;
  // Stable counting sort of the particles by cell (memory order), for cache-friendly transfers
  // and an order that does not depend on history. With several threads each counts and moves
  // the particles of its part of the array (the advection's parts); a cell takes part 0's
  // particles first, then part 1's, so the order is the serial one.
  void sortParticles();
  std::vector<std::vector<std::uint32_t>> partCounts;  ///< per part, per cell of the slab

  // Pushes particles out of the bodies. Per cell (CSR: bodiesAt[c] to bodiesAt[c + 1] in
  // bodyList), the bodies whose bounds reach it; only those are tested.
  std::vector<std::uint32_t> bodiesAt, bodyList, bodyListFill;
  std::vector<int> enforceRowLo, enforceRowHi;  ///< scratch of enforceBodies: faces per row
  void pushParticlesOut(const std::vector<PreparedBody>& bodies);

  void classify(const std::vector<PreparedBody>& bodies);

  // Per rigid body: 1 when it gets the liquid's force (cells.cpp: it has a submerged cell), else
  // 0 (doubles, for the reduction over blocks). A body that does not even touch the liquid (no
  // cell holding particles or sharing a face with a liquid cell) is in air: its cells are
  // classified as air (p = 0), so that pressure cannot reach it through the cells of another
  // body it touches (a box resting on a floating box). Net nodes are not bodies of the grid
  // (node_coupling.hpp).
  std::vector<double> inLiquid;
  void dryBodiesOutOfLiquid(const std::vector<PreparedBody>& bodies);

  void particlesToGrid();
  // The particle loops of the two transfers, compiled twice (VRFLOW_FLUID_HOT in their
  // definitions): call them only from particles.cpp, where the load-time choice is made.
  void splatParticles();
  void sampleAndAdvectParticles(double dt);
  // The particles [p0, p1) of both loops; splatRange adds to face planes planeLo to planeHi
  // only.
  void splatRange(std::size_t p0, std::size_t p1, int planeLo, int planeHi);
  void sampleAndAdvectRange(double dt, std::size_t p0, std::size_t p1, bool storeCells);

  // Fills faces without a value from the mean of valid neighbours, `layers` rings deep. Only
  // rows (j, k) with a valid face in them or next to them can gain values; the others (deep in
  // air) are skipped.
  std::vector<unsigned char> rowState;  // per row: bit 0 some face valid, bit 1 every face valid
  std::vector<std::size_t> filled;
  std::vector<std::vector<std::size_t>> filledPerThread;
  void extrapolate(std::vector<double>* field, int layers);
  // One plane of a pass of extrapolate(): fills faces of plane k, listing them in `out`.
  void fillPlane(int a, int k, double* value, const unsigned char* ok,
                 std::vector<std::size_t>& out) const;

  // Rigid motion on the faces of bodies, of kinematic bodies' cells and between a body's cell
  // and air; `kinematicOnly` re-imposes it on kinematic bodies after gravity (a moving wall does
  // not fall). Only the faces in each body's bounds (one cell wider) can be affected; a face in
  // several bodies' bounds gets the same value each time.
  void enforceBodies(const std::vector<PreparedBody>& bodies, bool kinematicOnly = false);

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
  void project(double dt);

  void measureDivergence();

  void markProjectedFaces();

  void gridToParticlesAndAdvect(double dt);

  void refreshOutput() {
    posOut.resize(pos.size());
    for (std::size_t q = 0; q < pos.size(); ++q) posOut[q] = static_cast<float>(pos[q]);
  }
};

}  // namespace vrflow::fluid
