// fluid/fluid: the grid fluid as one module with the ports of an animator and an interactor.
// In: `objects` (rigid bodies with their shape resources; mass-spring nets when node-radius > 0).
// Out: `forces` (one force event per coupled rigid body per iteration, duration = dt, and one
// massspring node-forces event per net) and
// `fluid` (its own fluid object, then its particles as a dynamic Mesh resource of xyz floats
// with no triangles; with `particle-regions` a b c, one fluid object per box of an a x b x c
// split of the grid, each with its own particles and the bounds of them, so that a route
// filter sends a viewer only the regions it sees; with `surface` on, each region's part of the
// liquid's surface as a dynamic Mesh with triangles instead of its particles).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "blocks.hpp"
#include "final_state.hpp"
#include "node_forces.hpp"
#include "vrflow/fluid/solver.hpp"
#include "vrflow/fluid/surface.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"
#include "world.hpp"

namespace {

using namespace vrflow;

bool parseCounts(const std::string& text, std::array<int, 3>& out) {
  std::istringstream in(text);
  std::array<int, 3> v{};
  std::string rest;
  if (!(in >> v[0] >> v[1] >> v[2]) || (in >> rest)) return false;
  out = v;
  return true;
}

// The particles cut into the boxes of an a x b x c split of the grid's bounds, in their order,
// with each box's bounds: those of its particles, or the box itself when it holds none.
struct Regions {
  std::array<int, 3> counts{1, 1, 1};
  msg::Aabb grid{};
  std::vector<std::vector<float>> xyz;
  std::vector<msg::Aabb> bounds;

  int size() const { return counts[0] * counts[1] * counts[2]; }

  msg::Aabb box(int r) const {
    const std::array<int, 3> cell{r % counts[0], (r / counts[0]) % counts[1],
                                  r / (counts[0] * counts[1])};
    msg::Aabb b{};
    for (std::size_t a = 0; a < 3; ++a) {
      const double step = (grid.max[a] - grid.min[a]) / counts[a];
      b.min[a] = grid.min[a] + step * cell[a];
      b.max[a] = cell[a] + 1 == counts[a] ? grid.max[a] : grid.min[a] + step * (cell[a] + 1);
    }
    return b;
  }

  void split(const std::vector<float>& all) {
    xyz.assign(static_cast<std::size_t>(size()), {});
    std::vector<msg::Aabb> tight(xyz.size());
    std::vector<bool> any(xyz.size(), false);
    for (std::size_t i = 0; i + 2 < all.size(); i += 3) {
      int r = 0, stride = 1;
      for (std::size_t a = 0; a < 3; ++a) {
        const double t = (all[i + a] - grid.min[a]) / (grid.max[a] - grid.min[a]);
        const int k = std::clamp(static_cast<int>(std::floor(t * counts[a])), 0, counts[a] - 1);
        r += k * stride;
        stride *= counts[a];
      }
      auto& out = xyz[static_cast<std::size_t>(r)];
      out.insert(out.end(), all.begin() + static_cast<std::ptrdiff_t>(i),
                 all.begin() + static_cast<std::ptrdiff_t>(i + 3));
      auto& b = tight[static_cast<std::size_t>(r)];
      for (std::size_t a = 0; a < 3; ++a) {
        const double v = all[i + a];
        b.min[a] = any[static_cast<std::size_t>(r)] ? std::min(b.min[a], v) : v;
        b.max[a] = any[static_cast<std::size_t>(r)] ? std::max(b.max[a], v) : v;
      }
      any[static_cast<std::size_t>(r)] = true;
    }
    bounds.resize(xyz.size());
    for (int r = 0; r < size(); ++r) {
      const auto k = static_cast<std::size_t>(r);
      bounds[k] = any[k] ? tight[k] : box(r);
    }
  }
};

int fail(const std::string& message) {
  std::fprintf(stderr, "vrflow-fluid: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (fluid::mpirunRank() > 0) return fluid::runRankWorker(argc, argv);  // blocks via mpirun
  Module module;
  auto& objectsIn = module.addInput("objects");
  auto& forcesOut = module.addOutput("forces");
  auto& objectsOut = module.addOutput("fluid");
  auto& interestOut = module.addOutput("interest");
  if (!initOrReport(module, "vrflow-fluid")) return 2;
  fluid::FluidSettings s;
  s.nx = static_cast<int>(module.params().getInt("nx"));
  s.ny = static_cast<int>(module.params().getInt("ny"));
  s.nz = static_cast<int>(module.params().getInt("nz"));
  s.cellSize = module.params().getFloat("cell-size");
  s.density = module.params().getFloat("density");
  s.flipRatio = module.params().getFloat("flip-ratio");
  s.particlesPerCell = static_cast<int>(module.params().getInt("particles-per-cell"));
  s.maxParticles = static_cast<int>(module.params().getInt("max-particles"));
  s.cgTolerance = module.params().getFloat("cg-tolerance");
  s.cgMaxIterations = static_cast<int>(module.params().getInt("cg-max-iterations"));
  // The manifest lists the choices; the module checks them again rather than guess.
  if (!fluid::parsePreconditioner(module.params().getString("preconditioner"), s.preconditioner)) {
    return fail("preconditioner '" + module.params().getString("preconditioner") +
                "' is neither multigrid nor mic0");
  }
  s.volumeCorrection = module.params().getFloat("volume-correction");
  s.origin = module.params().getVec3("origin");
  s.gravity = module.params().getVec3("gravity");
  const msg::Aabb fill{module.params().getVec3("fill-min"), module.params().getVec3("fill-max")};
  const double dt = module.params().getFloat("dt");
  const auto particlesEvery = module.params().getInt("particles-every");
  const double nodeRadius = module.params().getFloat("node-radius");
  Regions regions;
  if (!parseCounts(module.params().getString("particle-regions"), regions.counts)) {
    return fail("particle-regions must be three whole numbers (boxes along x, y and z)");
  }
  for (std::size_t a = 0; a < 3; ++a) {
    const int cells = a == 0 ? s.nx : a == 1 ? s.ny : s.nz;
    if (regions.counts[a] < 1 || regions.counts[a] > cells) {
      return fail("particle-regions: " + std::to_string(regions.counts[a]) + " boxes along " +
                  "xyz"[a] + " (there must be 1 to " + std::to_string(cells) +
                  ", the grid's cells)");
    }
  }

  const auto blocks = module.params().getInt("blocks");
  const std::string job = module.params().getString("job");
  // Threads and ranks share the cores: 0 gives each block its share of them.
  const auto threads = module.params().getInt("threads");
  const auto cores = static_cast<std::int64_t>(std::max(1u, std::thread::hardware_concurrency()));
  s.threads = static_cast<int>(threads > 0   ? threads
                               : job.empty() ? std::max<std::int64_t>(1, cores / blocks)
                                             : 1);
  const bool withSurface = module.params().getString("surface") == "on";
  if (withSurface && !job.empty()) {
    return fail("surface = on with job = '" + job +
                "': a block of a job holds only its own particles (use blocks instead)");
  }
  const fluid::SurfaceSettings surfaceSettings =
      fluid::surfaceSettings(s, static_cast<int>(module.params().getInt("surface-resolution")));
  if (!job.empty() && blocks > 1) {
    return fail("blocks = " + std::to_string(blocks) + " with job = '" + job +
                "': a module of an MPI job is one block of it (leave blocks at 1)");
  }

  if (auto status = fluid::validateSettings(s); !status) return fail(status.error().message);
  if (auto status = fluid::validateTimeStep(s, dt); !status) return fail(status.error().message);
  std::unique_ptr<fluid::FluidSolver> serial;
  std::unique_ptr<fluid::BlockGroup> group;
  std::unique_ptr<fluid::JobBlock> jobBlock;
  if (!job.empty()) {
    auto started = fluid::JobBlock::start(job, s, fill);
    if (!started) return fail(started.error().message);
    jobBlock = std::move(started.value());
  } else if (blocks <= 1) {
    auto created = fluid::FluidSolver::create(s);
    if (!created) return fail(created.error().message);
    serial = std::move(created.value());
    if (auto status = serial->addLiquidBox(fill); !status) return fail(status.error().message);
  } else {
    auto started = fluid::BlockGroup::start(static_cast<int>(blocks), s, fill);
    if (!started) return fail(started.error().message);
    group = std::move(started.value());
  }
  fluid::FluidSolver& solver = serial ? *serial : group ? group->solver() : jobBlock->solver();
  auto stepBlocks = [&](const fluid::BlockStep& request) {
    return group      ? group->step(request)
           : jobBlock ? jobBlock->step(request)
                      : fluid::stepBlock(solver, request);
  };
  // The blocks of a job make the collective queries together: block 0's file parameters decide.
  const bool first = !jobBlock || jobBlock->rank() == 0;
  const std::string statsPath = module.params().getString("stats");
  const std::string statePath = module.params().getString("state-file");
  const bool withStats = jobBlock ? jobBlock->fromFirst(!statsPath.empty()) : !statsPath.empty();
  const bool withState = jobBlock ? jobBlock->fromFirst(!statePath.empty()) : !statePath.empty();

  std::ofstream stats;
  if (const auto& path = statsPath; first && withStats) {
    stats.open(path, std::ios::trunc);
    if (!stats) return fail("cannot write the stats file " + path);
    stats << "iteration,time,cg_iterations,cg_residual,fluid_cells,body_cells,volume,"
             "max_particle_speed,bodies\n";
  }

  // The final state needs the volume before the first step; a query-only step is collective.
  fluid::FinalState finalState;
  finalState.settings = s;
  if (withState) {
    fluid::BlockStep query;
    query.queryOnly = true;
    query.stats = true;
    auto queried = stepBlocks(query);
    if (!queried) return fail(queried.error().message);
    finalState.initialVolume = queried->volume;
  }

  fluid::World world(nodeRadius);
  regions.grid = solver.bounds();
  // The fluid couples the objects whose bounds meet its grid widened by kLocalBodyMargin cells
  // (what lies beyond touches no cell and no particle); a block of a job, those near its slab
  // only, and it says so on `interest` (for a route filter). So both forms hold, report and
  // write to the state file the same bodies. A block's particles are its own, its fluid
  // object's bounds its slab.
  const msg::Aabb near = [&] {
    if (jobBlock) return jobBlock->slab(fluid::kLocalBodyMargin);
    msg::Aabb box = solver.bounds();
    const double margin = fluid::kLocalBodyMargin * s.cellSize;
    for (std::size_t a = 0; a < 3; ++a) {
      box.min[a] -= margin;
      box.max[a] += margin;
    }
    return box;
  }();
  const msg::Aabb ownBounds = jobBlock ? jobBlock->slab(0) : solver.bounds();
  std::vector<std::uint64_t> fluidIds, particlesIds;
  for (int r = 0; r < regions.size(); ++r) {
    fluidIds.push_back(module.newId());
    particlesIds.push_back(module.newId());
  }
  bool warnedUncoupled = false;
  double time = 0.0;
  bool ending = false;
  for (;;) {
    // The blocks of a job stop together: one that stopped waiting would leave the others in the
    // step's collective calls.
    bool go = !ending && module.wait();
    if (jobBlock) go = jobBlock->agree(go);
    if (!go) break;
    if (objectsIn.connected()) {
      const Message& in = module.get(objectsIn);
      if (in.valid()) {
        if (auto status = world.apply(in.view()); !status) return fail(status.error().message);
      }
    }
    const auto bodies = world.rigidBodies(&near);
    const auto points = world.pointMasses(&near);
    if (!warnedUncoupled && module.iteration() >= 2) {
      for (const auto& line : world.uncoupled()) {
        std::fprintf(stderr, "vrflow-fluid: not coupled: %s\n", line.c_str());
        warnedUncoupled = true;
      }
    }
    const bool sendParticles =
        particlesEvery > 0 &&
        (module.iteration() % static_cast<std::uint64_t>(particlesEvery) == 0);
    fluid::BlockStep request;
    request.dt = dt;
    request.bodies = bodies;
    // Captured users after the bodies, in one solver only (a block's step travels as bytes,
    // which carry shapes, not users' fields).
    if (!group && !jobBlock) {
      const auto users = world.users(&near);
      request.bodies.insert(request.bodies.end(), users.begin(), users.end());
    }
    request.points = points;
    request.gatherParticles = sendParticles && !jobBlock;
    request.stats = withStats;
    auto stepped = stepBlocks(request);
    if (!stepped) return fail(stepped.error().message);
    time += dt;
    if (withState) {
      finalState.bodies = bodies;
      finalState.forces = stepped->forces;
      ++finalState.steps;
    }

    auto forces = module.newMessage(256 + 128 * bodies.size());
    forces.builder().setSimTime(time);
    forces.builder().setTimeStep(dt);
    // The step returns the bodies' forces first, then the nodes'.
    for (std::size_t b = 0; b < bodies.size() && b < stepped->forces.size(); ++b) {
      const auto& f = stepped->forces[b];
      if (f.cells > 0 && !bodies[b].kinematic && f.reported) {
        forces.builder().addForce(f.id, {f.force, f.torque, f.point, f.duration});
      }
    }
    if (!points.empty() && stepped->forces.size() >= request.bodies.size() + points.size()) {
      // A net is held whole by a block, so its nodes are reported by the same one.
      std::vector<fluid::PointMass> reportedPoints;
      std::vector<fluid::BodyForce> nodeForces;
      for (std::size_t p = 0; p < points.size(); ++p) {
        const auto& f = stepped->forces[request.bodies.size() + p];
        if (!f.reported) continue;
        reportedPoints.push_back(points[p]);
        nodeForces.push_back(f);
      }
      fluid::addNodeForceEvents(forces.builder(), reportedPoints, nodeForces);
    }
    if (!module.put(forcesOut, std::move(forces))) {
      ending = true;
      continue;
    }

    const auto& xyz = jobBlock ? solver.particlePositions() : stepped->particles;
    // With the surface, each region's part of it replaces its particles (and their bounds).
    std::vector<fluid::SurfaceRegion> surface;
    std::size_t payloadBytes = sendParticles ? xyz.size() * sizeof(float) : 0;
    if (withSurface && sendParticles) {
      auto mesh = fluid::extractSurface(xyz, surfaceSettings);
      if (!mesh) return fail(mesh.error().message);
      surface = fluid::splitSurface(*mesh, regions.grid, regions.counts);
      payloadBytes = 4 * (mesh->xyz.size() + mesh->indices.size()) + 64 * surface.size();
    }
    auto out = module.newMessage(512 + 160 * fluidIds.size() + payloadBytes);
    out.builder().setSimTime(time);
    out.builder().setTimeStep(dt);
    const bool split = regions.size() > 1;
    if (split && sendParticles && !withSurface) regions.split(xyz);
    const auto addPayload = [&](std::size_t r, const std::vector<float>& particles) {
      if (withSurface) {
        out.builder().addMesh(particlesIds[r], true, surface[r].mesh.xyz, surface[r].mesh.indices);
      } else {
        out.builder().addMesh(particlesIds[r], true, particles, {});
      }
    };
    for (std::size_t r = 0; r < fluidIds.size(); ++r) {
      // One region: the object's bounds are the grid's, sent once. Regions: the bounds of their
      // particles, sent with every copy of them (the meshes first, as a route filter wants).
      if (module.iteration() == 0 || (split && sendParticles)) {
        const bool add = module.iteration() == 0;
        const msg::Aabb bounds = !split                    ? ownBounds
                                 : !surface.empty()        ? surface[r].bounds
                                 : !regions.bounds.empty() ? regions.bounds[r]
                                                           : regions.box(static_cast<int>(r));
        if (sendParticles) addPayload(r, split && !withSurface ? regions.xyz[r] : xyz);
        auto object = out.builder().addObject(fluidIds[r], msg::fluidType(),
                                              add ? msg::ObjectOp::Add : msg::ObjectOp::Update);
        object.set(msg::FluidParam::kBounds, bounds);
        if (add) {
          object.set(withSurface ? msg::FluidParam::kSurface : msg::FluidParam::kParticles,
                     particlesIds[r]);
        }
      } else if (sendParticles) {
        addPayload(r, xyz);
      }
    }
    if (!module.put(objectsOut, std::move(out))) {
      ending = true;
      continue;
    }
    if (jobBlock && module.iteration() == 0 && interestOut.connected()) {
      char text[160];
      std::snprintf(text, sizeof text, "%.17g %.17g %.17g %.17g %.17g %.17g", near.min[0],
                    near.min[1], near.min[2], near.max[0], near.max[1], near.max[2]);
      auto volume = module.newMessage();
      volume.builder().setStampsOnly(true);
      volume.builder().addStringStamp("interest", text);
      if (!module.put(interestOut, std::move(volume))) {
        ending = true;
        continue;
      }
    }

    if (stats.is_open()) {
      const auto& st = solver.lastStats();
      stats << module.iteration() << ',' << time << ',' << st.cgIterations << ',' << st.cgResidual
            << ',' << st.fluidCells << ',' << st.bodyCells << ',' << stepped->volume << ','
            << stepped->maxSpeed << ',' << bodies.size() << '\n';
    }
  }
  if (withState) {
    fluid::BlockStep query;
    query.queryOnly = true;
    query.stats = true;
    query.gatherParticles = true;
    auto queried = stepBlocks(query);
    if (!queried) return fail(queried.error().message);
    if (jobBlock) jobBlock->gatherBodies(finalState.bodies, finalState.forces);
    finalState.time = time;
    finalState.volume = queried->volume;
    finalState.maxSpeed = queried->maxSpeed;
    finalState.particles = std::move(queried->particles);
    if (first) {
      if (auto status = fluid::writeFinalState(statePath, finalState); !status) {
        if (group) group->stop();
        return fail(status.error().message);
      }
    }
  }
  if (group) group->stop();
  if (jobBlock) jobBlock->stop();
  return module.exitStatus();
}
