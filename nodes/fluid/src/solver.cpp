#include "vrflow/fluid/solver.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "bodies.hpp"
#include "grid.hpp"
#include "pressure.hpp"

namespace vrflow::fluid {

using detail::Grid;
using detail::PreparedBody;

struct FluidSolver::Impl {
  FluidSettings settings;
  Grid grid;
  std::vector<double> pos;  // xyz per particle
  std::vector<double> vel;  // xyz per particle
  std::vector<float> posOut;
  std::vector<double> u[3], uOld[3], weight[3];
  std::vector<unsigned char> valid[3];
  std::vector<int> faceBody[3];
  std::vector<int> cellBody;
  std::vector<unsigned char> kind;
  std::vector<double> cellDensity;
  detail::PressureSystem system;
  std::vector<double> rhs, pressure;
  StepStats stats;
  double maxDiv = 0.0;
  double lastDt = 1.0;
  PressureComm* comm = nullptr;
  std::uint64_t rng = 1;

  double nextJitter() {  // splitmix64 -> [-0.5, 0.5)
    std::uint64_t z = (rng += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53 - 0.5;
  }

  // Face position of component `a` at integer face coordinates.
  msg::Vec3 facePosition(int a, int i, int j, int k) const {
    const double h = grid.h;
    msg::Vec3 x{grid.ox + (i + 0.5) * h, grid.oy + (j + 0.5) * h, grid.oz + (k + 0.5) * h};
    x[a] -= 0.5 * h;
    return x;
  }

  // Trilinear weights of component `a` at world point x: base indices and fractions.
  void stencil(int a, const double* x, int base[3], double frac[3]) const {
    for (int d = 0; d < 3; ++d) {
      const double o = (d == 0 ? grid.ox : d == 1 ? grid.oy : grid.oz);
      double c = (x[d] - o) / grid.h - (d == a ? 0.0 : 0.5);
      const int hi = grid.fdim(a, d) - 1;
      c = std::clamp(c, 0.0, static_cast<double>(hi));
      int b = static_cast<int>(std::floor(c));
      if (b >= hi) b = hi - 1;
      if (b < 0) b = 0;
      base[d] = b;
      frac[d] = hi == 0 ? 0.0 : c - b;
    }
  }

  double sample(const std::vector<double>& field, int a, const double* x) const {
    int b[3];
    double f[3];
    stencil(a, x, b, f);
    double v = 0.0;
    for (int dk = 0; dk < 2; ++dk) {
      for (int dj = 0; dj < 2; ++dj) {
        for (int di = 0; di < 2; ++di) {
          const double w = (di ? f[0] : 1 - f[0]) * (dj ? f[1] : 1 - f[1]) * (dk ? f[2] : 1 - f[2]);
          v += w * field[grid.face(a, b[0] + di, b[1] + dj, b[2] + dk)];
        }
      }
    }
    return v;
  }

  void sampleVelocity(const std::vector<double>* field, const double* x, double* out) const {
    for (int a = 0; a < 3; ++a) out[a] = sample(field[a], a, x);
  }

  void clampToDomain(double* x) const {
    const double eps = 1e-3 * grid.h;
    const double lo[3] = {grid.ox, grid.oy, grid.oz};
    const int n[3] = {grid.nx, grid.ny, grid.nz};
    for (int d = 0; d < 3; ++d) {
      x[d] = std::clamp(x[d], lo[d] + eps, lo[d] + n[d] * grid.h - eps);
    }
  }

  bool cellOf(const double* x, int& i, int& j, int& k) const {
    i = static_cast<int>(std::floor((x[0] - grid.ox) / grid.h));
    j = static_cast<int>(std::floor((x[1] - grid.oy) / grid.h));
    k = static_cast<int>(std::floor((x[2] - grid.oz) / grid.h));
    return i >= 0 && j >= 0 && k >= 0 && i < grid.nx && j < grid.ny && k < grid.nz;
  }

  void zeroWalls(std::vector<double>* field) const {
    for (int a = 0; a < 3; ++a) {
      const int n = grid.fdim(a, a) - 1;
      for (int k = 0; k < grid.fdim(a, 2); ++k) {
        for (int j = 0; j < grid.fdim(a, 1); ++j) {
          for (int i = 0; i < grid.fdim(a, 0); ++i) {
            const int along = a == 0 ? i : a == 1 ? j : k;
            if (along == 0 || along == n) field[a][grid.face(a, i, j, k)] = 0.0;
          }
        }
      }
    }
  }

  void pushParticlesOut(const std::vector<PreparedBody>& bodies) {
    const std::size_t n = pos.size() / 3;
    for (const auto& body : bodies) {
      for (std::size_t p = 0; p < n; ++p) {
        double* x = &pos[3 * p];
        if (!detail::inBounds(body.bounds, x)) continue;
        detail::pushOut(body, x, 0.25 * grid.h);
        clampToDomain(x);
      }
    }
  }

  std::vector<int> particlesInCell;
  std::vector<double> divTarget;  // per cell, times 1/dt

  void classify(const std::vector<PreparedBody>& bodies) {
    detail::rasterise(grid, bodies, cellBody, faceBody);
    std::fill(kind.begin(), kind.end(), detail::kAir);
    for (std::size_t c = 0; c < kind.size(); ++c) {
      if (cellBody[c] >= 0) {
        kind[c] = detail::kBody;
        cellDensity[c] = bodies[static_cast<std::size_t>(cellBody[c])].density;
      } else {
        cellDensity[c] = settings.density;
      }
    }
    particlesInCell.assign(kind.size(), 0);
    const std::size_t n = pos.size() / 3;
    for (std::size_t p = 0; p < n; ++p) {
      int i, j, k;
      if (cellOf(&pos[3 * p], i, j, k)) {
        const std::size_t c = grid.cell(i, j, k);
        ++particlesInCell[c];
        if (kind[c] == detail::kAir) kind[c] = detail::kLiquid;
      }
    }
    // Volume control: each liquid cell away from the surface asks for a divergence that brings
    // its particle count back to particlesPerCell (cells next to air are partly full by nature).
    divTarget.assign(kind.size(), 0.0);
    const double n0 = settings.particlesPerCell;
    const std::size_t sy = static_cast<std::size_t>(grid.nx), sz = sy * grid.ny;
    long long sum = 0, count = 0;
    for (int k = 0; k < grid.nz; ++k) {
      for (int j = 0; j < grid.ny; ++j) {
        for (int i = 0; i < grid.nx; ++i) {
          const std::size_t c = grid.cell(i, j, k);
          if (kind[c] != detail::kLiquid) continue;
          if ((i > 0 && kind[c - 1] == detail::kAir) || (i + 1 < grid.nx && kind[c + 1] == detail::kAir) ||
              (j > 0 && kind[c - sy] == detail::kAir) || (j + 1 < grid.ny && kind[c + sy] == detail::kAir) ||
              (k > 0 && kind[c - sz] == detail::kAir) || (k + 1 < grid.nz && kind[c + sz] == detail::kAir)) {
            continue;
          }
          sum += particlesInCell[c];
          ++count;
          const double density = std::min(2.0, particlesInCell[c] / n0);
          divTarget[c] = -settings.volumeCorrection * (1.0 - density);  // times 1/dt in project()
        }
      }
    }
    stats.particleDensity =
        count > 0 ? static_cast<double>(sum) / (static_cast<double>(count) * n0) : 1.0;
  }

  void particlesToGrid() {
    for (int a = 0; a < 3; ++a) {
      std::fill(u[a].begin(), u[a].end(), 0.0);
      std::fill(weight[a].begin(), weight[a].end(), 0.0);
    }
    const std::size_t n = pos.size() / 3;
    for (std::size_t p = 0; p < n; ++p) {
      const double* x = &pos[3 * p];
      for (int a = 0; a < 3; ++a) {
        int b[3];
        double f[3];
        stencil(a, x, b, f);
        const double va = vel[3 * p + a];
        for (int dk = 0; dk < 2; ++dk) {
          for (int dj = 0; dj < 2; ++dj) {
            for (int di = 0; di < 2; ++di) {
              const double w =
                  (di ? f[0] : 1 - f[0]) * (dj ? f[1] : 1 - f[1]) * (dk ? f[2] : 1 - f[2]);
              const std::size_t fi = grid.face(a, b[0] + di, b[1] + dj, b[2] + dk);
              u[a][fi] += w * va;
              weight[a][fi] += w;
            }
          }
        }
      }
    }
    for (int a = 0; a < 3; ++a) {
      for (std::size_t f = 0; f < u[a].size(); ++f) {
        if (weight[a][f] > 1e-9) {
          u[a][f] /= weight[a][f];
          valid[a][f] = 1;
        } else {
          u[a][f] = 0.0;
          valid[a][f] = 0;
        }
      }
    }
  }

  // Fills faces without a value from the mean of valid neighbours, `layers` rings deep.
  void extrapolate(std::vector<double>* field, int layers) {
    for (int a = 0; a < 3; ++a) {
      const int dx = grid.fdim(a, 0), dy = grid.fdim(a, 1), dz = grid.fdim(a, 2);
      std::vector<unsigned char> next;
      for (int layer = 0; layer < layers; ++layer) {
        next = valid[a];
        for (int k = 0; k < dz; ++k) {
          for (int j = 0; j < dy; ++j) {
            for (int i = 0; i < dx; ++i) {
              const std::size_t f = grid.face(a, i, j, k);
              if (valid[a][f]) continue;
              double sum = 0.0;
              int count = 0;
              const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k},
                                    {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
              for (const auto& q : nb) {
                if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= dx || q[1] >= dy || q[2] >= dz) {
                  continue;
                }
                const std::size_t g = grid.face(a, q[0], q[1], q[2]);
                if (valid[a][g]) {
                  sum += field[a][g];
                  ++count;
                }
              }
              if (count > 0) {
                field[a][f] = sum / count;
                next[f] = 1;
              }
            }
          }
        }
        valid[a].swap(next);
      }
    }
  }

  void enforceBodies(const std::vector<PreparedBody>& bodies) {
    for (int a = 0; a < 3; ++a) {
      for (int k = 0; k < grid.fdim(a, 2); ++k) {
        for (int j = 0; j < grid.fdim(a, 1); ++j) {
          for (int i = 0; i < grid.fdim(a, 0); ++i) {
            const std::size_t f = grid.face(a, i, j, k);
            const int b = faceBody[a][f];
            if (b < 0) continue;
            u[a][f] = detail::rigidVelocity(bodies[static_cast<std::size_t>(b)],
                                            facePosition(a, i, j, k))[a];
          }
        }
      }
    }
  }

  bool unknown(std::size_t c) const { return kind[c] != detail::kAir; }

  // Pressure projection with variable density (bodies carry their own) and p = 0 in air.
  void project(double dt) {
    const std::size_t n = grid.cells();
    auto& A = system;
    A.diag.assign(n, 0.0);
    A.ax.assign(n, 0.0);
    A.ay.assign(n, 0.0);
    A.az.assign(n, 0.0);
    rhs.assign(n, 0.0);
    const double h = grid.h;
    stats.targetDivergence = -settings.volumeCorrection * (1.0 - stats.particleDensity) / dt;
    lastDt = dt;
    const std::size_t stride[3] = {1, static_cast<std::size_t>(grid.nx),
                                   static_cast<std::size_t>(grid.nx) * grid.ny};
    for (int k = 0; k < grid.nz; ++k) {
      for (int j = 0; j < grid.ny; ++j) {
        for (int i = 0; i < grid.nx; ++i) {
          const std::size_t c = grid.cell(i, j, k);
          if (!unknown(c)) continue;
          rhs[c] = -((u[0][grid.face(0, i + 1, j, k)] - u[0][grid.face(0, i, j, k)]) +
                     (u[1][grid.face(1, i, j + 1, k)] - u[1][grid.face(1, i, j, k)]) +
                     (u[2][grid.face(2, i, j, k + 1)] - u[2][grid.face(2, i, j, k)])) / h;
          rhs[c] += divTarget[c] / dt;
          const int idx[3] = {i, j, k};
          const int dims[3] = {grid.nx, grid.ny, grid.nz};
          for (int a = 0; a < 3; ++a) {
            for (int side = -1; side <= 1; side += 2) {
              const int m = idx[a] + side;
              if (m < 0 || m >= dims[a]) continue;  // wall: Neumann, no coefficient
              const std::size_t nbr = side > 0 ? c + stride[a] : c - stride[a];
              const double rho = unknown(nbr) ? 0.5 * (cellDensity[c] + cellDensity[nbr])
                                              : cellDensity[c];
              const double beta = dt / (rho * h * h);
              A.diag[c] += beta;
              if (side > 0 && unknown(nbr)) {
                (a == 0 ? A.ax : a == 1 ? A.ay : A.az)[c] = -beta;
              }
            }
          }
        }
      }
    }
    const auto outcome = detail::solvePressure(grid, A, rhs, pressure, settings.cgTolerance,
                                               settings.cgMaxIterations, comm);
    if (comm) {
      std::vector<int> kStart(static_cast<std::size_t>(comm->size()) + 1);
      for (int r = 0; r <= comm->size(); ++r) {
        int k0, k1;
        slabOf(grid.nz, std::min(r, comm->size() - 1), comm->size(), k0, k1);
        kStart[static_cast<std::size_t>(r)] = r == comm->size() ? grid.nz : k0;
      }
      comm->allGather(pressure, grid.nx * grid.ny, kStart);
    }
    stats.cgIterations = outcome.iterations;
    stats.cgResidual = outcome.residual;
    stats.cgConverged = outcome.converged;
    stats.bytesTouched = outcome.bytesTouched;
    // Subtract the pressure gradient on every interior face next to an unknown cell.
    for (int a = 0; a < 3; ++a) {
      for (int k = 0; k < grid.fdim(a, 2); ++k) {
        for (int j = 0; j < grid.fdim(a, 1); ++j) {
          for (int i = 0; i < grid.fdim(a, 0); ++i) {
            const int along = a == 0 ? i : a == 1 ? j : k;
            if (along == 0 || along == grid.fdim(a, a) - 1) continue;
            const std::size_t hi = grid.cell(i, j, k);
            const std::size_t lo = hi - stride[a];
            const bool ulo = unknown(lo), uhi = unknown(hi);
            if (!ulo && !uhi) continue;
            const double rho = (ulo && uhi) ? 0.5 * (cellDensity[lo] + cellDensity[hi])
                                            : (ulo ? cellDensity[lo] : cellDensity[hi]);
            const double plo = ulo ? pressure[lo] : 0.0, phi = uhi ? pressure[hi] : 0.0;
            u[a][grid.face(a, i, j, k)] -= dt / (rho * h) * (phi - plo);
          }
        }
      }
    }
  }

  void measureDivergence() {
    maxDiv = 0.0;
    stats.fluidCells = 0;
    stats.bodyCells = 0;
    for (int k = 0; k < grid.nz; ++k) {
      for (int j = 0; j < grid.ny; ++j) {
        for (int i = 0; i < grid.nx; ++i) {
          const std::size_t c = grid.cell(i, j, k);
          if (kind[c] == detail::kBody) ++stats.bodyCells;
          if (kind[c] != detail::kLiquid) continue;
          ++stats.fluidCells;
          const double div = ((u[0][grid.face(0, i + 1, j, k)] - u[0][grid.face(0, i, j, k)]) +
                              (u[1][grid.face(1, i, j + 1, k)] - u[1][grid.face(1, i, j, k)]) +
                              (u[2][grid.face(2, i, j, k + 1)] - u[2][grid.face(2, i, j, k)])) /
                             grid.h;
          maxDiv = std::max(maxDiv, std::abs(div - divTarget[c] / lastDt));
        }
      }
    }
    stats.maxSpeed = 0.0;
    for (int a = 0; a < 3; ++a) {
      for (int k = 0; k < grid.fdim(a, 2); ++k) {
        for (int j = 0; j < grid.fdim(a, 1); ++j) {
          for (int i = 0; i < grid.fdim(a, 0); ++i) {
            const int along = a == 0 ? i : a == 1 ? j : k;
            if (along == 0 || along == grid.fdim(a, a) - 1) continue;
            const std::size_t hi = grid.cell(i, j, k);
            const std::size_t lo = hi - (a == 0   ? 1
                                         : a == 1 ? static_cast<std::size_t>(grid.nx)
                                                  : static_cast<std::size_t>(grid.nx) * grid.ny);
            if (kind[lo] != detail::kLiquid && kind[hi] != detail::kLiquid) continue;
            stats.maxSpeed = std::max(stats.maxSpeed, std::abs(u[a][grid.face(a, i, j, k)]));
          }
        }
      }
    }
  }

  void gridToParticlesAndAdvect(double dt) {
    const double flip = settings.flipRatio;
    const std::size_t n = pos.size() / 3;
    for (std::size_t p = 0; p < n; ++p) {
      double* x = &pos[3 * p];
      double* v = &vel[3 * p];
      double un[3], uo[3];
      sampleVelocity(u, x, un);
      sampleVelocity(uOld, x, uo);
      for (int a = 0; a < 3; ++a) v[a] = flip * (v[a] + un[a] - uo[a]) + (1.0 - flip) * un[a];
      // Midpoint (RK2) through the divergence-free grid velocity.
      double mid[3] = {x[0] + 0.5 * dt * un[0], x[1] + 0.5 * dt * un[1], x[2] + 0.5 * dt * un[2]};
      clampToDomain(mid);
      double um[3];
      sampleVelocity(u, mid, um);
      for (int a = 0; a < 3; ++a) x[a] += dt * um[a];
      clampToDomain(x);
    }
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
  for (int a = 0; a < 3; ++a) {
    impl->u[a].assign(g.faces(a), 0.0);
    impl->uOld[a].assign(g.faces(a), 0.0);
    impl->weight[a].assign(g.faces(a), 0.0);
    impl->valid[a].assign(g.faces(a), 0);
    impl->faceBody[a].assign(g.faces(a), -1);
  }
  impl->cellBody.assign(g.cells(), -1);
  impl->kind.assign(g.cells(), detail::kAir);
  impl->cellDensity.assign(g.cells(), settings.density);
  impl->pressure.assign(g.cells(), 0.0);
  return std::unique_ptr<FluidSolver>(new FluidSolver(std::move(impl)));
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
  std::size_t added = 0;
  std::vector<std::size_t> seeded;
  for (int k = 0; k < g.nz; ++k) {
    for (int j = 0; j < g.ny; ++j) {
      for (int i = 0; i < g.nx; ++i) {
        const double c[3] = {g.ox + (i + 0.5) * g.h, g.oy + (j + 0.5) * g.h, g.oz + (k + 0.5) * g.h};
        bool inside = true;
        for (int d = 0; d < 3; ++d) inside = inside && c[d] >= box.min[d] && c[d] <= box.max[d];
        if (inside) seeded.push_back(g.cell(i, j, k));
      }
    }
  }
  const std::size_t total = m.pos.size() / 3 + seeded.size() * static_cast<std::size_t>(per * per * per);
  if (total > static_cast<std::size_t>(m.settings.maxParticles)) {
    return makeError("fluid: the liquid box needs " + std::to_string(total) +
                     " particles, more than the limit of " +
                     std::to_string(m.settings.maxParticles));
  }
  if (seeded.empty()) {
    return makeError("fluid: the liquid box holds no cell centre of the grid");
  }
  for (const std::size_t c : seeded) {
    const int i = static_cast<int>(c % static_cast<std::size_t>(g.nx));
    const int j = static_cast<int>((c / static_cast<std::size_t>(g.nx)) % static_cast<std::size_t>(g.ny));
    const int k = static_cast<int>(c / (static_cast<std::size_t>(g.nx) * g.ny));
    for (int sk = 0; sk < per; ++sk) {
      for (int sj = 0; sj < per; ++sj) {
        for (int si = 0; si < per; ++si) {
          const int s[3] = {si, sj, sk};
          const int idx[3] = {i, j, k};
          const double o[3] = {g.ox, g.oy, g.oz};
          for (int d = 0; d < 3; ++d) {
            const double sub = (s[d] + 0.5 + 0.5 * m.nextJitter()) / per;
            m.pos.push_back(o[d] + (idx[d] + sub) * g.h);
            m.vel.push_back(0.0);
          }
          ++added;
        }
      }
    }
  }
  m.posOut.resize(m.pos.size());
  for (std::size_t q = 0; q < m.pos.size(); ++q) m.posOut[q] = static_cast<float>(m.pos[q]);
  return {};
}

Result<std::vector<BodyForce>> FluidSolver::step(double dt, const std::vector<RigidBody>& bodies,
                                                 const std::vector<PointMass>& points) {
  auto& m = *impl_;
  if (auto status = validateTimeStep(m.settings, dt); !status) return status.error();
  std::vector<PreparedBody> prepared;
  prepared.reserve(bodies.size() + points.size());
  for (const auto& body : bodies) {
    auto p = detail::prepareBody(body);
    if (!p) return p.error();
    prepared.push_back(std::move(*p));
  }
  for (const auto& point : points) {
    auto p = detail::preparePoint(point);
    if (!p) return p.error();
    prepared.push_back(std::move(*p));
  }

  m.pushParticlesOut(prepared);
  m.classify(prepared);
  m.particlesToGrid();
  m.extrapolate(m.u, 2);
  m.enforceBodies(prepared);
  m.zeroWalls(m.u);
  for (int a = 0; a < 3; ++a) m.uOld[a] = m.u[a];
  for (int a = 0; a < 3; ++a) {
    const double dv = m.settings.gravity[a] * dt;
    for (double& x : m.u[a]) x += dv;
  }
  m.zeroWalls(m.u);
  m.project(dt);
  m.measureDivergence();

  std::vector<BodyForce> forces;
  forces.reserve(prepared.size());
  for (std::size_t b = 0; b < prepared.size(); ++b) {
    forces.push_back(detail::bodyForce(m.grid, prepared[b], static_cast<int>(b), m.faceBody, m.u,
                                       m.uOld, m.settings.gravity, dt));
  }

  // Faces touching no liquid or body cell keep the pre-projection value; give them the
  // projected neighbours' instead so particles near the surface see the new field.
  for (int a = 0; a < 3; ++a) {
    const auto& g = m.grid;
    for (int k = 0; k < g.fdim(a, 2); ++k) {
      for (int j = 0; j < g.fdim(a, 1); ++j) {
        for (int i = 0; i < g.fdim(a, 0); ++i) {
          const std::size_t f = g.face(a, i, j, k);
          const int along = a == 0 ? i : a == 1 ? j : k;
          bool touches = false;
          if (along > 0) touches = touches || m.unknown(g.cell(i - (a == 0), j - (a == 1), k - (a == 2)));
          if (along < g.fdim(a, a) - 1) touches = touches || m.unknown(g.cell(i, j, k));
          m.valid[a][f] = touches ? 1 : 0;
        }
      }
    }
  }
  m.extrapolate(m.u, 2);
  m.zeroWalls(m.u);
  m.gridToParticlesAndAdvect(dt);
  for (std::size_t q = 0; q < m.pos.size(); ++q) m.posOut[q] = static_cast<float>(m.pos[q]);
  return forces;
}

void FluidSolver::setPressureComm(PressureComm* comm) { impl_->comm = comm; }
const FluidSettings& FluidSolver::settings() const { return impl_->settings; }
const StepStats& FluidSolver::lastStats() const { return impl_->stats; }
const std::vector<float>& FluidSolver::particlePositions() const { return impl_->posOut; }
std::size_t FluidSolver::particleCount() const { return impl_->pos.size() / 3; }

double FluidSolver::liquidVolume() const {
  const auto& m = *impl_;
  std::vector<unsigned char> occupied(m.grid.cells(), 0);
  const std::size_t n = m.pos.size() / 3;
  for (std::size_t p = 0; p < n; ++p) {
    int i, j, k;
    if (m.cellOf(&m.pos[3 * p], i, j, k)) occupied[m.grid.cell(i, j, k)] = 1;
  }
  std::size_t count = 0;
  for (const auto o : occupied) count += o;
  return static_cast<double>(count) * m.grid.h * m.grid.h * m.grid.h;
}

double FluidSolver::maxParticleSpeed() const {
  const auto& m = *impl_;
  double best = 0.0;
  for (std::size_t p = 0; p + 2 < m.vel.size(); p += 3) {
    best = std::max(best, std::sqrt(m.vel[p] * m.vel[p] + m.vel[p + 1] * m.vel[p + 1] +
                                    m.vel[p + 2] * m.vel[p + 2]));
  }
  return best;
}

double FluidSolver::surfaceHeightAt(double x, double z) const {
  const auto& m = *impl_;
  const int ci = static_cast<int>(std::floor((x - m.grid.ox) / m.grid.h));
  const int ck = static_cast<int>(std::floor((z - m.grid.oz) / m.grid.h));
  double top = m.grid.oy;
  for (std::size_t p = 0; p + 2 < m.pos.size(); p += 3) {
    const int i = static_cast<int>(std::floor((m.pos[p] - m.grid.ox) / m.grid.h));
    const int k = static_cast<int>(std::floor((m.pos[p + 2] - m.grid.oz) / m.grid.h));
    if (i == ci && k == ck) top = std::max(top, m.pos[p + 1]);
  }
  return top;
}

double FluidSolver::maxDivergence() const { return impl_->maxDiv; }

msg::Aabb FluidSolver::bounds() const {
  const auto& g = impl_->grid;
  return {{g.ox, g.oy, g.oz}, {g.ox + g.nx * g.h, g.oy + g.ny * g.h, g.oz + g.nz * g.h}};
}

}  // namespace vrflow::fluid
