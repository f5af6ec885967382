// vrflow-fluid-blocks: the fluid as blocks over MPI ranks (mpirun -np N), on a fixed scene: a dam
// break in a tank with `--bodies` boxes dropped into it, integrated here (translation only, walls
// and floor as contacts) from the forces the blocks return. Prints one JSON line on rank 0: the
// scene, timing, pressure-solve numbers and what the blocks agree on (volume, particle centroid,
// body heights, a digest of the particle positions). `--serial` runs the library without a
// BlockComm (on one rank) to compare with `mpirun -np 1`. `--local-bodies` gives each block only
// the boxes near its slab (FluidSolver::setLocalBodies, as the fluid's job modules do) and sums
// the reported forces over the ranks to integrate every box on every rank. `--bodies-in-liquid`
// places the boxes in the liquid column instead of above the tank (light ones floating at the
// surface, heavy ones under it), so that they are coupled from the first step; the JSON's
// `wet_bodies_first_timed` counts the boxes the fluid pushed on in the first timed step.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "vrflow/fluid/mpi_block_comm.hpp"
#include "vrflow/fluid/solver.hpp"

namespace {

using namespace vrflow;

struct Options {
  int nx = 32, ny = 64, nz = 32;
  double h = 1.0 / 32;
  int steps = 50;
  int warmup = 3;
  int bodies = 0;
  int maxParticles = 200000;
  int threads = 1;
  double dt = 0.005;
  bool serial = false;
  bool localBodies = false;
  bool bodiesInLiquid = false;
  fluid::FluidPreconditioner preconditioner = fluid::FluidSettings{}.preconditioner;
};

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&](double& v) {
      if (i + 1 >= argc) return false;
      char* end = nullptr;
      v = std::strtod(argv[++i], &end);
      return end && *end == '\0' && std::isfinite(v);
    };
    double v = 0;
    if (a == "--local-bodies") {
      o.localBodies = true;
    } else if (a == "--bodies-in-liquid") {
      o.bodiesInLiquid = true;
    } else if (a == "--serial") {
      o.serial = true;
    } else if (a == "--nx" || a == "--ny" || a == "--nz" || a == "--steps" || a == "--bodies" ||
               a == "--warmup" || a == "--max-particles" || a == "--threads") {
      if (!next(v)) return false;
      const int n = static_cast<int>(v);
      (a == "--nx"        ? o.nx
       : a == "--ny"      ? o.ny
       : a == "--nz"      ? o.nz
       : a == "--steps"   ? o.steps
       : a == "--warmup"  ? o.warmup
       : a == "--bodies"  ? o.bodies
       : a == "--threads" ? o.threads
                          : o.maxParticles) = n;
    } else if (a == "--preconditioner") {
      if (i + 1 >= argc || !fluid::parsePreconditioner(argv[++i], o.preconditioner)) return false;
    } else if (a == "--h") {
      if (!next(o.h)) return false;
    } else if (a == "--dt") {
      if (!next(o.dt)) return false;
    } else {
      return false;
    }
  }
  return o.steps > 0 && o.bodies >= 0 && o.warmup >= 0;
}

struct Box {
  fluid::RigidBody body;
  double half;
};

std::vector<Box> makeBoxes(const Options& o, const msg::Aabb& tank) {
  std::vector<Box> boxes;
  const double half = 1.5 * o.h;
  const double sx = tank.max[0] - tank.min[0], sy = tank.max[1] - tank.min[1],
               sz = tank.max[2] - tank.min[2];
  for (int b = 0; b < o.bodies; ++b) {
    Box box;
    box.half = half;
    box.body.id = static_cast<std::uint64_t>(b + 1);
    box.body.shape = msg::Shape::box({half, half, half});
    const int col = b % 5, row = (b / 5) % 4, layer = b / 20;
    box.body.position = {tank.min[0] + sx * (0.1 + 0.8 * (col + 0.5) / 5.0),
                         tank.min[1] + sy * (0.6 + 0.08 * layer) + (row % 2) * 3 * half,
                         tank.min[2] + sz * (0.1 + 0.8 * (row + 0.5) / 4.0)};
    const double density = (b % 2 == 0) ? 500.0 : 2000.0;
    if (o.bodiesInLiquid) {
      // The liquid fills x in [0, sx / 2) and y in [0, sy / 2): four columns across it, five
      // rows along z; a light box floats at the surface, a heavy one starts half-way down.
      const int c = b % 4, r = (b / 4) % 5, level = b / 20;
      box.body.position = {tank.min[0] + sx * 0.5 * (c + 0.5) / 4.0,
                           tank.min[1] + sy * (b % 2 == 0 ? 0.5 : 0.25) - level * 3 * half,
                           tank.min[2] + sz * (0.1 + 0.8 * (r + 0.5) / 5.0)};
    }
    box.body.mass = density * 8 * half * half * half;
    boxes.push_back(box);
  }
  return boxes;
}

void integrate(Box& box, const fluid::BodyForce& f, double dt, const msg::Vec3& g,
               const msg::Aabb& tank) {
  for (int a = 0; a < 3; ++a) {
    box.body.linearVelocity[a] += (f.force[a] / box.body.mass + g[a]) * dt;
    box.body.position[a] += box.body.linearVelocity[a] * dt;
    const double lo = tank.min[a] + box.half, hi = tank.max[a] - box.half;
    if (box.body.position[a] < lo || box.body.position[a] > hi) {
      box.body.position[a] = std::clamp(box.body.position[a], lo, hi);
      box.body.linearVelocity[a] = 0.0;
    }
  }
}

std::uint64_t fnv(const std::vector<float>& values) {
  std::uint64_t hash = 1469598103934665603ull;
  const auto* bytes = reinterpret_cast<const unsigned char*>(values.data());
  for (std::size_t i = 0; i < values.size() * sizeof(float); ++i) {
    hash = (hash ^ bytes[i]) * 1099511628211ull;
  }
  return hash;
}

// This process's CPU time in seconds (on a loaded machine, wall time also counts the time other
// processes held the core).
double cpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  Options o;
  if (!parse(argc, argv, o)) {
    if (rank == 0) {
      std::fprintf(stderr,
                   "usage: vrflow-fluid-blocks [--nx N --ny N --nz N --h M --dt S --steps N "
                   "--warmup N --bodies N --max-particles N --threads N --serial --local-bodies "
                   "--bodies-in-liquid --preconditioner mic0|multigrid]\n");
    }
    MPI_Finalize();
    return 2;
  }
  if (o.serial && size != 1) {
    if (rank == 0) std::fprintf(stderr, "vrflow-fluid-blocks: --serial runs on one rank only\n");
    MPI_Finalize();
    return 2;
  }
  fluid::FluidSettings s;
  s.nx = o.nx;
  s.ny = o.ny;
  s.nz = o.nz;
  s.cellSize = o.h;
  s.maxParticles = o.maxParticles;
  s.threads = o.threads;
  s.preconditioner = o.preconditioner;
  auto created = fluid::FluidSolver::create(s);
  if (!created) {
    if (rank == 0)
      std::fprintf(stderr, "vrflow-fluid-blocks: %s\n", created.error().message.c_str());
    MPI_Finalize();
    return 1;
  }
  auto solver = std::move(created.value());
  fluid::MpiBlockComm comm(MPI_COMM_WORLD);
  if (!o.serial) {
    solver->setLocalBodies(o.localBodies);
    if (auto status = solver->setBlockComm(&comm); !status) {
      if (rank == 0)
        std::fprintf(stderr, "vrflow-fluid-blocks: %s\n", status.error().message.c_str());
      MPI_Finalize();
      return 1;
    }
  }
  const auto tank = solver->bounds();
  const msg::Aabb liquid{tank.min,
                         {tank.min[0] + 0.5 * (tank.max[0] - tank.min[0]),
                          tank.min[1] + 0.5 * (tank.max[1] - tank.min[1]), tank.max[2]}};
  if (auto status = solver->addLiquidBox(liquid); !status) {
    if (rank == 0)
      std::fprintf(stderr, "vrflow-fluid-blocks: %s\n", status.error().message.c_str());
    MPI_Finalize();
    return 1;
  }
  auto boxes = makeBoxes(o, tank);
  double timed = 0.0, cpuTimed = 0.0, pressureTime = 0.0, bytes = 0.0;
  long long cgIterations = 0;
  int timedSteps = 0;
  int wetFirstTimed = -1;
  for (int step = 0; step < o.steps; ++step) {
    std::vector<fluid::RigidBody> bodies;
    std::vector<std::size_t> held;  // the boxes this block was given
    int k0 = 0, k1 = s.nz;
    if (!o.serial) fluid::slabOf(s.nz, rank, size, k0, k1);
    const double zLo = tank.min[2] + (k0 - fluid::kLocalBodyMargin) * s.cellSize;
    const double zHi = tank.min[2] + (k1 + fluid::kLocalBodyMargin) * s.cellSize;
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      const double z = boxes[b].body.position[2], half = boxes[b].half;
      if (o.localBodies && (z + half < zLo || z - half > zHi)) continue;
      bodies.push_back(boxes[b].body);
      held.push_back(b);
    }
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = MPI_Wtime(), c0 = cpuSeconds();
    auto forces = solver->step(o.dt, bodies);
    const double c1 = cpuSeconds();
    MPI_Barrier(MPI_COMM_WORLD);
    const double t1 = MPI_Wtime();
    if (!forces) {
      if (rank == 0)
        std::fprintf(stderr, "vrflow-fluid-blocks: %s\n", forces.error().message.c_str());
      MPI_Finalize();
      return 1;
    }
    // Every box's force on every rank: with local bodies, from the rank that reports it (the
    // others add zeros, so the sum is that force's bits).
    std::vector<fluid::BodyForce> all(boxes.size());
    for (std::size_t i = 0; i < held.size(); ++i) {
      if ((*forces)[i].reported) all[held[i]] = (*forces)[i];
    }
    if (o.localBodies) {
      std::vector<double> sums(boxes.size() * 3);
      for (std::size_t b = 0; b < boxes.size(); ++b) {
        for (int a = 0; a < 3; ++a) sums[3 * b + a] = all[b].force[a];
      }
      MPI_Allreduce(MPI_IN_PLACE, sums.data(), static_cast<int>(sums.size()), MPI_DOUBLE, MPI_SUM,
                    MPI_COMM_WORLD);
      for (std::size_t b = 0; b < boxes.size(); ++b) {
        for (int a = 0; a < 3; ++a) all[b].force[a] = sums[3 * b + a];
      }
    }
    if (step == o.warmup) {
      // A box the fluid pushes on is wet (a box in air gets exactly zero force).
      wetFirstTimed = 0;
      for (const auto& f : all)
        wetFirstTimed += f.force[0] != 0.0 || f.force[1] != 0.0 || f.force[2] != 0.0;
    }
    for (std::size_t b = 0; b < boxes.size(); ++b)
      integrate(boxes[b], all[b], o.dt, s.gravity, tank);
    const auto& st = solver->lastStats();
    if (step >= o.warmup) {
      timed += t1 - t0;
      cpuTimed += c1 - c0;
      double pt = st.pressureSeconds;
      MPI_Allreduce(MPI_IN_PLACE, &pt, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
      pressureTime += pt;
      double b = static_cast<double>(st.bytesTouched);
      MPI_Allreduce(MPI_IN_PLACE, &b, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
      bytes += b;
      cgIterations += st.cgIterations;
      ++timedSteps;
    }
  }
  const double volume = solver->liquidVolume();
  const double speed = solver->maxParticleSpeed();
  const std::size_t particles = solver->particleCount();
  const auto all = solver->gatherParticlePositions();
  if (rank == 0) {
    double meanY = 0.0;
    for (std::size_t p = 1; p < all.size(); p += 3) meanY += all[p];
    meanY /= static_cast<double>(all.size() / 3);
    std::string ys;
    for (const auto& b : boxes) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%s%.9g", ys.empty() ? "" : ",", b.body.position[1]);
      ys += buf;
    }
    const int n = std::max(1, timedSteps);
    std::printf(
        "{\"grid\":\"%dx%dx%d\",\"rigid\":%d,\"ranks\":%d,\"threads\":%d,"
        "\"preconditioner\":\"%s\",\"serial\":%s,"
        "\"steps\":%d,\"particles\":%zu,\"ms_per_step\":%.3f,\"cpu_ms_per_step\":%.3f,\"cg_"
        "iterations\":%.1f,"
        "\"pressure_ms_per_step\":%.3f,\"cg_bytes_per_step\":%.0f,\"bandwidth_gbs\":%.3f,"
        "\"volume\":%.9g,\"mean_y\":%.9g,\"max_speed\":%.6g,\"body_y\":[%s],"
        "\"wet_bodies_first_timed\":%d,\"digest\":\"%016llx\"}\n",
        o.nx, o.ny, o.nz, o.bodies, size, o.threads, fluid::preconditionerName(o.preconditioner),
        o.serial ? "true" : "false", o.steps, particles, 1e3 * timed / n, 1e3 * cpuTimed / n,
        static_cast<double>(cgIterations) / n, 1e3 * pressureTime / n, bytes / n,
        pressureTime > 0 ? bytes / pressureTime / 1e9 : 0.0, volume, meanY, speed, ys.c_str(),
        wetFirstTimed, static_cast<unsigned long long>(fnv(all)));
  }
  MPI_Finalize();
  return 0;
}
