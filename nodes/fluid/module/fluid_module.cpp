// fluid/fluid: the grid fluid as one module with the ports of an animator and an interactor.
// In: `objects` (rigid bodies with their shape resources; mass-spring nets when node-radius > 0).
// Out: `forces` (one force event per coupled rigid body per iteration, duration = dt, and one
// massspring node-forces event per net) and
// `objects` (its own fluid object, then its particles as a dynamic Mesh resource of xyz floats
// with no triangles).
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "blocks.hpp"
#include "final_state.hpp"
#include "node_forces.hpp"
#include "vrflow/fluid/solver.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/module.hpp"
#include "world.hpp"

namespace {

using namespace vrflow;

bool parseVec3(const std::string& text, msg::Vec3& out) {
  std::istringstream in(text);
  msg::Vec3 v{};
  if (!(in >> v[0] >> v[1] >> v[2])) return false;
  out = v;
  return true;
}

int fail(const std::string& message) {
  std::fprintf(stderr, "vrflow-fluid: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "--block-worker") {
    return fluid::runBlockWorker(argc, argv);
  }
  Module module;
  auto& objectsIn = module.addInput("objects");
  auto& forcesOut = module.addOutput("forces");
  auto& objectsOut = module.addOutput("fluid");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "vrflow-fluid: %s\n", status.error().message.c_str());
    return 2;
  }
  fluid::FluidSettings s;
  s.nx = static_cast<int>(module.paramInt("nx", s.nx));
  s.ny = static_cast<int>(module.paramInt("ny", s.ny));
  s.nz = static_cast<int>(module.paramInt("nz", s.nz));
  s.cellSize = module.paramDouble("cell-size", s.cellSize);
  s.density = module.paramDouble("density", s.density);
  s.flipRatio = module.paramDouble("flip-ratio", s.flipRatio);
  s.particlesPerCell = static_cast<int>(module.paramInt("particles-per-cell", s.particlesPerCell));
  s.maxParticles = static_cast<int>(module.paramInt("max-particles", s.maxParticles));
  s.cgTolerance = module.paramDouble("cg-tolerance", s.cgTolerance);
  s.cgMaxIterations = static_cast<int>(module.paramInt("cg-max-iterations", s.cgMaxIterations));
  s.volumeCorrection = module.paramDouble("volume-correction", s.volumeCorrection);
  msg::Aabb fill{{0, 0, 0}, {1, 0.5, 1}};
  if (!parseVec3(module.param("origin", "0 0 0"), s.origin) ||
      !parseVec3(module.param("gravity", "0 -9.81 0"), s.gravity) ||
      !parseVec3(module.param("fill-min", "0 0 0"), fill.min) ||
      !parseVec3(module.param("fill-max", "1 0.5 1"), fill.max)) {
    return fail("origin, gravity, fill-min and fill-max must be three numbers each");
  }
  const double dt = module.paramDouble("dt", 0.01);
  const auto particlesEvery = module.paramInt("particles-every", 1);
  const double nodeRadius = module.paramDouble("node-radius", 0.0);

  const auto blocks = module.paramInt("blocks", 1);

  if (auto status = fluid::validateSettings(s); !status) return fail(status.error().message);
  if (auto status = fluid::validateTimeStep(s, dt); !status) return fail(status.error().message);
  std::unique_ptr<fluid::FluidSolver> serial;
  std::unique_ptr<fluid::BlockGroup> group;
  if (blocks <= 1) {
    auto created = fluid::FluidSolver::create(s);
    if (!created) return fail(created.error().message);
    serial = std::move(created.value());
    if (auto status = serial->addLiquidBox(fill); !status) return fail(status.error().message);
  } else {
    auto started = fluid::BlockGroup::start(argv[0], static_cast<int>(blocks), s, fill);
    if (!started) return fail(started.error().message);
    group = std::move(started.value());
  }
  fluid::FluidSolver& solver = serial ? *serial : group->solver();

  std::ofstream stats;
  if (const auto path = module.param("stats"); !path.empty()) {
    stats.open(path, std::ios::trunc);
    if (!stats) return fail("cannot write the stats file " + path);
    stats << "iteration,time,cg_iterations,cg_residual,fluid_cells,body_cells,volume,"
             "max_particle_speed,bodies\n";
  }

  // The final state needs the volume before the first step; a query-only step is collective.
  const std::string statePath = module.param("state-file");
  fluid::FinalState finalState;
  finalState.settings = s;
  if (!statePath.empty()) {
    fluid::BlockStep query;
    query.queryOnly = true;
    query.stats = true;
    auto queried = group ? group->step(query) : fluid::stepBlock(solver, query);
    if (!queried) return fail(queried.error().message);
    finalState.initialVolume = queried->volume;
  }

  fluid::World world(nodeRadius);
  const std::uint64_t fluidId = module.newId();
  const std::uint64_t particlesId = module.newId();
  bool warnedUncoupled = false;
  double time = 0.0;
  while (module.wait()) {
    if (objectsIn.connected()) {
      const Message& in = module.get(objectsIn);
      if (in.valid()) {
        if (auto status = world.apply(in.view()); !status) return fail(status.error().message);
      }
    }
    const auto bodies = world.rigidBodies();
    const auto points = world.pointMasses();
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
    request.points = points;
    request.gatherParticles = sendParticles;
    request.stats = stats.is_open();
    auto stepped = group ? group->step(request) : fluid::stepBlock(solver, request);
    if (!stepped) return fail(stepped.error().message);
    time += dt;
    if (!statePath.empty()) {
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
      if (f.cells > 0 && !bodies[b].kinematic) {
        forces.builder().addForce(f.id, {f.force, f.torque, f.point, f.duration});
      }
    }
    if (!points.empty() && stepped->forces.size() >= bodies.size()) {
      const std::vector<fluid::BodyForce> nodeForces(
          stepped->forces.begin() + static_cast<std::ptrdiff_t>(bodies.size()),
          stepped->forces.end());
      fluid::addNodeForceEvents(forces.builder(), points, nodeForces);
    }
    if (!module.put(forcesOut, std::move(forces))) break;

    const auto& xyz = stepped->particles;
    auto out = module.newMessage(512 + (sendParticles ? xyz.size() * sizeof(float) : 0));
    out.builder().setSimTime(time);
    out.builder().setTimeStep(dt);
    if (module.iteration() == 0) {
      out.builder()
          .addObject(fluidId, msg::fluidType(), msg::ObjectOp::Add)
          .set(msg::FluidParam::kBounds, solver.bounds())
          .set(msg::FluidParam::kParticles, particlesId);
    }
    if (sendParticles) out.builder().addMesh(particlesId, true, xyz, {});
    if (!module.put(objectsOut, std::move(out))) break;

    if (stats.is_open()) {
      const auto& st = solver.lastStats();
      stats << module.iteration() << ',' << time << ',' << st.cgIterations << ',' << st.cgResidual
            << ',' << st.fluidCells << ',' << st.bodyCells << ',' << stepped->volume << ','
            << stepped->maxSpeed << ',' << bodies.size() << '\n';
    }
  }
  if (!statePath.empty()) {
    fluid::BlockStep query;
    query.queryOnly = true;
    query.stats = true;
    query.gatherParticles = true;
    auto queried = group ? group->step(query) : fluid::stepBlock(solver, query);
    if (!queried) return fail(queried.error().message);
    finalState.time = time;
    finalState.volume = queried->volume;
    finalState.maxSpeed = queried->maxSpeed;
    finalState.particles = std::move(queried->particles);
    if (auto status = fluid::writeFinalState(statePath, finalState); !status) {
      if (group) group->stop();
      return fail(status.error().message);
    }
  }
  if (group) group->stop();
  return module.exitStatus();
}
