#include "vrflow/fluid/solver.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "node_coupling.hpp"
#include "solver_impl.hpp"

namespace vrflow::fluid {

FluidSolver::FluidSolver(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
FluidSolver::~FluidSolver() = default;

Result<std::unique_ptr<FluidSolver>> FluidSolver::create(const FluidSettings& settings) {
  if (auto status = validateSettings(settings); !status) return status.error();
  auto impl = std::make_unique<Impl>();
  impl->settings = settings;
  impl->workers = std::make_unique<detail::Workers>(settings.threads);
  impl->pcg.workers = impl->workers.get();
  impl->pcg.preconditioner = settings.preconditioner;
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

void FluidSolver::setLocalBodies(bool local) {
  impl_->localBodies = local;
}

void FluidSolver::Impl::uniteBodies(const BodyKeys& bodies, BodyUnion& out) {
  out.keys.clear();
  out.holder.clear();
  out.ofBody.clear();
  if (!comm || !localBodies) return;
  // Every block sends its list to every block as records (rank, id high, id low, index): whole
  // numbers below 2^32, exact in doubles.
  constexpr int kRecord = 4;
  std::vector<double> mine;
  mine.reserve(bodies.size() * kRecord);
  for (const auto& body : bodies) {
    mine.push_back(comm->rank());
    mine.push_back(static_cast<double>(body.first >> 32));
    mine.push_back(static_cast<double>(body.first & 0xffffffffu));
    mine.push_back(body.second);
  }
  const std::vector<std::vector<double>> outgoing(static_cast<std::size_t>(comm->size()), mine);
  const auto all = comm->exchange(outgoing, kRecord);
  struct Held {
    std::pair<std::uint64_t, std::uint32_t> key;
    int rank;
  };
  std::vector<Held> held;
  held.reserve(all.size() / kRecord);
  for (std::size_t r = 0; r + kRecord <= all.size(); r += kRecord) {
    const auto id =
        (static_cast<std::uint64_t>(all[r + 1]) << 32) | static_cast<std::uint64_t>(all[r + 2]);
    held.push_back({{id, static_cast<std::uint32_t>(all[r + 3])}, static_cast<int>(all[r])});
  }
  std::sort(held.begin(), held.end(), [](const Held& a, const Held& b) {
    return a.key != b.key ? a.key < b.key : a.rank < b.rank;
  });
  for (const auto& h : held) {
    if (!out.keys.empty() && out.keys.back() == h.key) continue;  // a higher block holds it too
    out.keys.push_back(h.key);
    out.holder.push_back(h.rank);
  }
  for (const auto& key : bodies) {
    out.ofBody.push_back(static_cast<std::size_t>(
        std::lower_bound(out.keys.begin(), out.keys.end(), key) - out.keys.begin()));
  }
}

void FluidSolver::Impl::combineOver(const BodyUnion& over, std::vector<double>& values,
                                    std::size_t width, bool maximum) {
  if (!comm) return;
  if (!localBodies) {  // every block holds the same list
    if (values.empty()) return;
    maximum ? comm->max(values) : comm->sum(values);
    return;
  }
  if (over.keys.empty()) return;  // no block holds a body
  // A block that does not hold a body adds 0 (or its maximum 0), as a block holding it with no
  // face in its planes would: the same bits as when every block holds every body.
  unionScratch.assign(over.keys.size() * width, 0.0);
  for (std::size_t b = 0; b < over.ofBody.size(); ++b) {
    std::copy_n(values.begin() + static_cast<std::ptrdiff_t>(b * width), width,
                unionScratch.begin() + static_cast<std::ptrdiff_t>(over.ofBody[b] * width));
  }
  maximum ? comm->max(unionScratch) : comm->sum(unionScratch);
  for (std::size_t b = 0; b < over.ofBody.size(); ++b) {
    std::copy_n(unionScratch.begin() + static_cast<std::ptrdiff_t>(over.ofBody[b] * width), width,
                values.begin() + static_cast<std::ptrdiff_t>(b * width));
  }
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
  prepared.reserve(bodies.size());
  Impl::BodyKeys bodyKeys, nodeKeys;
  for (const auto& body : bodies) {
    auto p = detail::prepareBody(body, m.settings.density);
    if (!p) return p.error();
    prepared.push_back(std::move(*p));
    bodyKeys.emplace_back(body.id, 0u);
  }
  // Nodes are checked as bodies are, then coupled on their own (node_coupling.hpp).
  for (const auto& point : points) {
    if (auto p = detail::preparePoint(point); !p) return p.error();
    nodeKeys.emplace_back(point.id, point.index);
  }

  m.uniteBodies(bodyKeys, m.bodyUnion);
  m.uniteBodies(nodeKeys, m.nodeUnion);
  m.pushParticlesOut(prepared);
  m.migrate();
  m.sortParticles();
  m.classify(prepared);
  m.particlesToGrid();
  m.extrapolate(m.u, 2);
  m.enforceBodies(prepared);
  m.zeroWalls(m.u);
  // The nodes' forces from the liquid as it is at the start of the step (level and velocity).
  const detail::NodeGridView view{&m.grid,
                                  m.k0,
                                  m.k1,
                                  {m.kEnd(0), m.kEnd(1), m.kEnd(2)},
                                  &m.kind,
                                  &m.particlesInCell,
                                  m.settings.particlesPerCell,
                                  m.u};
  std::vector<double> nodeSlots(points.size() * detail::kNodeSlots, 0.0);
  for (std::size_t p = 0; p < points.size(); ++p) {
    detail::gatherNodeSlots(view, points[p], &nodeSlots[p * detail::kNodeSlots]);
  }
  m.combineOver(m.nodeUnion, nodeSlots, detail::kNodeSlots, false);
  std::vector<BodyForce> nodeForces;
  nodeForces.reserve(points.size());
  for (std::size_t p = 0; p < points.size(); ++p) {
    nodeForces.push_back(detail::nodeForce(m.grid, points[p], &nodeSlots[p * detail::kNodeSlots],
                                           m.settings.density, m.settings.gravity, dt));
    nodeForces.back().reported = m.reports(m.nodeUnion, p);
  }
  for (int a = 0; a < 3; ++a) {
    const double dv = m.settings.gravity[static_cast<std::size_t>(a)] * dt;
    m.forOwnFacesThreaded(a, [&](std::size_t f, int, int, int) {
      m.uOld[a][f] = m.u[a][f];
      m.u[a][f] += dv;
    });
  }
  // The liquid gives the nodes' momentum (their reaction, before the projection).
  for (std::size_t p = 0; p < points.size(); ++p) {
    detail::applyNodeReaction(view, points[p], &nodeSlots[p * detail::kNodeSlots], nodeForces[p],
                              m.settings.density, dt, m.u);
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
  m.combineBodies(sums, detail::kBodySums, false);
  std::vector<BodyForce> forces;
  forces.reserve(prepared.size() + points.size());
  for (std::size_t b = 0; b < prepared.size(); ++b) {
    forces.push_back(detail::finishBodyForce(prepared[b], &sums[b * detail::kBodySums], dt));
    forces.back().reported = m.reports(m.bodyUnion, b);
    // A body in air: the faces it shares with a wet body's cells changed, but not for it.
    if (!prepared[b].kinematic && m.inLiquid[b] == 0.0) {
      forces.back().force = {};
      forces.back().torque = {};
    }
  }
  forces.insert(forces.end(), nodeForces.begin(), nodeForces.end());

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
