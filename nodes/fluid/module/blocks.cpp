#include "blocks.hpp"

#include <mpi.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "vrflow/fluid/mpi_block_comm.hpp"
#include "vrflow/ipc/join_contract.hpp"

namespace vrflow::fluid {
namespace {

// A flat little-endian byte stream for the step broadcast (same machine, same layout).
struct Writer {
  std::vector<char> bytes;
  template <typename T>
  void put(const T& v) {
    const char* p = reinterpret_cast<const char*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  void putBytes(const std::vector<std::byte>& b) {
    put(static_cast<std::uint64_t>(b.size()));
    const char* p = reinterpret_cast<const char*>(b.data());
    bytes.insert(bytes.end(), p, p + b.size());
  }
};

struct Reader {
  const std::vector<char>& bytes;
  std::size_t at = 0;
  bool ok = true;
  template <typename T>
  T get() {
    T v{};
    if (at + sizeof(T) > bytes.size()) {
      ok = false;
      return v;
    }
    std::memcpy(&v, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  std::vector<std::byte> getBytes() {
    const auto n = get<std::uint64_t>();
    if (!ok || at + n > bytes.size()) {
      ok = false;
      return {};
    }
    std::vector<std::byte> out(n);
    std::memcpy(out.data(), bytes.data() + at, n);
    at += n;
    return out;
  }
};

std::vector<char> encodeStep(const BlockStep& s) {
  Writer w;
  w.put(static_cast<std::uint8_t>(s.stop));
  w.put(static_cast<std::uint8_t>(s.queryOnly));
  w.put(s.dt);
  w.put(static_cast<std::uint8_t>(s.gatherParticles));
  w.put(static_cast<std::uint8_t>(s.stats));
  w.put(static_cast<std::uint64_t>(s.bodies.size()));
  for (const auto& b : s.bodies) {
    w.put(b.id);
    w.put(b.position);
    w.put(b.orientation);
    w.put(b.linearVelocity);
    w.put(b.angularVelocity);
    w.put(b.mass);
    // Kinematic bodies (mass 0) must stay kinematic on every block: a worker that took one for
    // a dynamic body of mass 0 would refuse the step alone and leave rank 0 waiting.
    w.put(static_cast<std::uint8_t>(b.kinematic));
    w.putBytes(msg::encodeShape(b.shape));
  }
  w.put(static_cast<std::uint64_t>(s.points.size()));
  for (const auto& p : s.points) w.put(p);
  return w.bytes;
}

bool decodeStep(const std::vector<char>& bytes, BlockStep& s) {
  Reader r{bytes};
  s.stop = r.get<std::uint8_t>() != 0;
  s.queryOnly = r.get<std::uint8_t>() != 0;
  s.dt = r.get<double>();
  s.gatherParticles = r.get<std::uint8_t>() != 0;
  s.stats = r.get<std::uint8_t>() != 0;
  const auto n = r.get<std::uint64_t>();
  s.bodies.clear();
  for (std::uint64_t i = 0; r.ok && i < n; ++i) {
    RigidBody b;
    b.id = r.get<std::uint64_t>();
    b.position = r.get<msg::Vec3>();
    b.orientation = r.get<msg::Quat>();
    b.linearVelocity = r.get<msg::Vec3>();
    b.angularVelocity = r.get<msg::Vec3>();
    b.mass = r.get<double>();
    b.kinematic = r.get<std::uint8_t>() != 0;
    auto shape = msg::decodeShape(r.getBytes());
    if (!shape) return false;
    b.shape = std::move(*shape);
    s.bodies.push_back(std::move(b));
  }
  const auto m = r.get<std::uint64_t>();
  s.points.clear();
  for (std::uint64_t i = 0; r.ok && i < m; ++i) s.points.push_back(r.get<PointMass>());
  return r.ok;
}

void broadcast(std::vector<char>& bytes, MPI_Comm comm) {
  std::uint64_t n = bytes.size();
  MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm);
  bytes.resize(n);
  MPI_Bcast(bytes.data(), static_cast<int>(n), MPI_CHAR, 0, comm);
}

void prepareMpi() {
  // Open MPI's I/O forwarding may write to the module's output pipes after vrflow stopped
  // reading them at the end of a run; a write error must not kill the process with SIGPIPE.
  std::signal(SIGPIPE, SIG_IGN);
  // Open MPI refuses root unless told (an MPI singleton: no mpirun told it).
  if (geteuid() == 0) {
    setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 0);
    setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 0);
  }
}

struct Setup {
  FluidSettings settings;
  msg::Aabb fill;
};

// After a step failed on this block: did every block fail it? They fail together when the
// step's input is bad (each checks the same broadcast input before any collective call); a block
// that fails alone leaves the others inside the step's collective calls, waiting for it forever.
// The agreement is a barrier on a communicator of its own, so it never meets a collective call
// of the step; blocks that failed together reach it at once, the bound only ends the wait for
// blocks that never come.
bool everyBlockFailed(MPI_Comm failures) {
  constexpr auto kBound = std::chrono::seconds(5);
  MPI_Request request = MPI_REQUEST_NULL;
  MPI_Ibarrier(failures, &request);
  const auto end = std::chrono::steady_clock::now() + kBound;
  for (;;) {
    int done = 0;
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done != 0) return true;
    if (std::chrono::steady_clock::now() >= end) return false;
    usleep(1000);
  }
}

}  // namespace

Result<BlockResult> stepBlock(FluidSolver& solver, const BlockStep& s) {
  BlockResult out;
  if (!s.queryOnly) {
    auto forces = solver.step(s.dt, s.bodies, s.points);
    if (!forces) return forces.error();
    out.forces = std::move(*forces);
  }
  if (s.gatherParticles) out.particles = solver.gatherParticlePositions();
  if (s.stats) {
    out.volume = solver.liquidVolume();
    out.maxSpeed = solver.maxParticleSpeed();
  }
  return out;
}

struct BlockGroup::Impl {
  MPI_Comm world = MPI_COMM_NULL;
  MPI_Comm failures = MPI_COMM_NULL;  ///< only for the agreement after a failed step
  int blocks = 0;
  std::unique_ptr<MpiBlockComm> comm;
  std::unique_ptr<FluidSolver> solver;
  bool stopped = false;
};

BlockGroup::BlockGroup(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BlockGroup::~BlockGroup() {
  stop();
}
FluidSolver& BlockGroup::solver() {
  return *impl_->solver;
}

Result<std::unique_ptr<BlockGroup>> BlockGroup::start(int blocks, const FluidSettings& settings,
                                                      const msg::Aabb& fill) {
  if (blocks < 2 || blocks > settings.nz) {
    return makeError("fluid: " + std::to_string(blocks) + " blocks for " +
                     std::to_string(settings.nz) + " z-planes: use 2 to nz blocks (1 = serial)");
  }
  if (mpirunRank() != 0) {
    return makeError("fluid: blocks = " + std::to_string(blocks) +
                     ", but this process is not rank 0 of the module's MPI ranks: vrflow starts "
                     "a module with blocks above 1 as that many ranks through mpirun (the "
                     "manifest's mpi-ranks); started another way, set blocks to 1");
  }
  prepareMpi();
  int argc = 0;
  char** argv = nullptr;
  MPI_Init(&argc, &argv);
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  auto impl = std::make_unique<Impl>();
  int size = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size != blocks) {
    MPI_Abort(MPI_COMM_WORLD, 2);  // the runtime starts exactly `blocks` ranks
  }
  MPI_Comm_dup(MPI_COMM_WORLD, &impl->world);
  impl->blocks = blocks;
  Setup setup{settings, fill};
  MPI_Bcast(&setup, sizeof setup, MPI_BYTE, 0, impl->world);
  MPI_Comm_dup(impl->world, &impl->failures);
  impl->comm = std::make_unique<MpiBlockComm>(impl->world);
  auto created = FluidSolver::create(settings);
  if (!created) return created.error();
  impl->solver = std::move(created.value());
  if (auto status = impl->solver->setBlockComm(impl->comm.get()); !status) return status.error();
  if (auto status = impl->solver->addLiquidBox(fill); !status) return status.error();
  return std::unique_ptr<BlockGroup>(new BlockGroup(std::move(impl)));
}

Result<BlockResult> BlockGroup::step(const BlockStep& s) {
  auto bytes = encodeStep(s);
  broadcast(bytes, impl_->world);
  auto result = stepBlock(*impl_->solver, s);
  if (!result && !impl_->stopped) {
    impl_->stopped = true;
    if (everyBlockFailed(impl_->failures)) {  // they left their loops: a clean end
      MPI_Finalize();
      return result;
    }
    // The workers are inside the step, waiting for this block: no MPI_Finalize. The module
    // reports the error and exits non-zero, and mpirun ends the workers when it sees rank 0
    // gone.
    return makeError(result.error().message + " (MPI block 0 of " + std::to_string(impl_->blocks) +
                     " alone: the other blocks did not fail with it; stopping them)");
  }
  return result;
}

void BlockGroup::stop() {
  if (impl_->stopped) return;
  impl_->stopped = true;
  BlockStep last;
  last.stop = true;
  auto bytes = encodeStep(last);
  broadcast(bytes, impl_->world);
  MPI_Finalize();  // as the workers do when told to stop
}

namespace {

// A worker's life on `world` (rank 0 is the module): the setup, then steps until told to stop.
int workerLoop(MPI_Comm world) {
  Setup setup;
  MPI_Bcast(&setup, sizeof setup, MPI_BYTE, 0, world);
  MPI_Comm failures = MPI_COMM_NULL;
  MPI_Comm_dup(world, &failures);
  MpiBlockComm comm(world);
  auto created = FluidSolver::create(setup.settings);
  if (!created) return 1;  // rank 0 made the same check and reports it
  auto solver = std::move(created.value());
  if (!solver->setBlockComm(&comm) || !solver->addLiquidBox(setup.fill)) return 1;
  for (;;) {
    std::vector<char> bytes;
    broadcast(bytes, world);
    BlockStep s;
    if (!decodeStep(bytes, s)) {
      std::fprintf(stderr, "vrflow-fluid: MPI block %d of %d: malformed step from rank 0\n",
                   comm.rank(), comm.size());
      MPI_Abort(world, 3);
    }
    if (s.stop) break;
    auto stepped = stepBlock(*solver, s);
    if (stepped) continue;
    // Failed with every block: rank 0 reports it. Failed alone: the other blocks wait for this
    // one inside the step; end the whole job, rank 0 with it, so that vrflow reports the module.
    if (everyBlockFailed(failures)) break;
    std::fprintf(stderr,
                 "vrflow-fluid: MPI block %d of %d failed alone: %s; aborting every block\n",
                 comm.rank(), comm.size(), stepped.error().message.c_str());
    MPI_Abort(world, 1);
  }
  MPI_Finalize();
  return 0;
}

}  // namespace

int mpirunRank() {
  // A module of several ranks is told so by the runtime's join contract (VRFLOW_MPI_RANKS).
  const auto contract = ipc::JoinContract::decodeEnvironment();
  if (!contract || contract->mpiRanks <= 0) return -1;
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK"}) {
    if (const char* rank = std::getenv(name)) return std::atoi(rank);
  }
  return -1;
}

int runRankWorker(int argc, char** argv) {
  // Die with rank 0's launcher as the module does; never touch the run's shared memory.
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  prepareMpi();
  MPI_Init(&argc, &argv);
  MPI_Comm world;
  MPI_Comm_dup(MPI_COMM_WORLD, &world);
  return workerLoop(world);
}

namespace {

// The blocks of a job that failed together each print their error and exit non-zero; mpirun
// kills the job's other ranks when the first of them exits, which could be before a slower one
// printed. So they finalise MPI together at exit, after every one has printed: a barrier first,
// then MPI_Finalize, from an atexit handler (the module prints on its way out of main).
void finalizeTogether() {
  MPI_Barrier(MPI_COMM_WORLD);
  MPI_Finalize();
}

void finalizeTogetherAtExit() {
  std::atexit(finalizeTogether);
}

}  // namespace

struct JobBlock::Impl {
  std::string job;
  MPI_Comm world = MPI_COMM_NULL;
  MPI_Comm failures = MPI_COMM_NULL;  ///< only for the agreement after a failed step
  int rank = 0;
  int size = 1;
  std::unique_ptr<MpiBlockComm> comm;
  std::unique_ptr<FluidSolver> solver;
  bool stopped = false;
};

JobBlock::JobBlock(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
JobBlock::~JobBlock() {
  if (impl_->stopped) return;
  // The module is ending on an error of its own (it printed it) without the others: they may be
  // inside a collective call waiting for this block, where MPI_Finalize would wait for them.
  if (impl_->size > 1) MPI_Abort(impl_->world, 1);
  stop();
}
int JobBlock::rank() const {
  return impl_->rank;
}
int JobBlock::size() const {
  return impl_->size;
}
FluidSolver& JobBlock::solver() {
  return *impl_->solver;
}

Result<std::unique_ptr<JobBlock>> JobBlock::start(const std::string& job,
                                                  const FluidSettings& settings,
                                                  const msg::Aabb& fill) {
  prepareMpi();
  // A job of one module is started as a plain process: an MPI singleton, which needs no
  // Open MPI daemon of its own (one would outlive the module for a moment).
  if (std::getenv("OMPI_COMM_WORLD_RANK") == nullptr && std::getenv("PMIX_RANK") == nullptr) {
    setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
  }
  int argc = 0;
  char** argv = nullptr;
  MPI_Init(&argc, &argv);
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  auto impl = std::make_unique<Impl>();
  impl->job = job;
  MPI_Comm_dup(MPI_COMM_WORLD, &impl->world);
  MPI_Comm_dup(MPI_COMM_WORLD, &impl->failures);
  MPI_Comm_rank(impl->world, &impl->rank);
  MPI_Comm_size(impl->world, &impl->size);
  // Every block checks the same settings (the job's modules share them through their composite),
  // so they fail together here and finalise together once each has printed the error.
  auto fail = [&](const std::string& message) -> Result<std::unique_ptr<JobBlock>> {
    finalizeTogetherAtExit();
    return makeError(message);
  };
  if (impl->size > settings.nz) {
    return fail("fluid: MPI job '" + job + "' has " + std::to_string(impl->size) +
                " modules for a grid of " + std::to_string(settings.nz) +
                " z-planes: each block needs at least one plane");
  }
  impl->comm = std::make_unique<MpiBlockComm>(impl->world);
  auto created = FluidSolver::create(settings);
  if (!created) return fail(created.error().message);
  impl->solver = std::move(created.value());
  if (auto status = impl->solver->setBlockComm(impl->comm.get()); !status) {
    return fail(status.error().message);
  }
  impl->solver->setLocalBodies(true);
  if (auto status = impl->solver->addLiquidBox(fill); !status) return fail(status.error().message);
  return std::unique_ptr<JobBlock>(new JobBlock(std::move(impl)));
}

msg::Aabb JobBlock::slab(int marginCells) const {
  const auto& s = impl_->solver->settings();
  int k0 = 0, k1 = 0;
  slabOf(s.nz, impl_->rank, impl_->size, k0, k1);
  const double margin = marginCells * s.cellSize;
  msg::Aabb box = impl_->solver->bounds();
  box.min[2] = s.origin[2] + k0 * s.cellSize;
  box.max[2] = s.origin[2] + k1 * s.cellSize;
  for (std::size_t a = 0; a < 3; ++a) {
    box.min[a] -= margin;
    box.max[a] += margin;
  }
  return box;
}

bool JobBlock::agree(bool mine) {
  int all = mine ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &all, 1, MPI_INT, MPI_MIN, impl_->world);
  return all != 0;
}

bool JobBlock::fromFirst(bool value) {
  int v = value ? 1 : 0;
  MPI_Bcast(&v, 1, MPI_INT, 0, impl_->world);
  return v != 0;
}

Result<BlockResult> JobBlock::step(const BlockStep& s) {
  auto result = stepBlock(*impl_->solver, s);
  if (result || impl_->stopped) return result;
  impl_->stopped = true;
  if (everyBlockFailed(impl_->failures)) {  // every block reports it and ends cleanly
    finalizeTogetherAtExit();
    return result;
  }
  std::fprintf(stderr,
               "vrflow-fluid: MPI block %d of %d (job '%s') failed alone: %s; aborting the job\n",
               impl_->rank, impl_->size, impl_->job.c_str(), result.error().message.c_str());
  MPI_Abort(impl_->world, 1);
  return result;  // not reached
}

void JobBlock::gatherBodies(std::vector<RigidBody>& bodies, std::vector<BodyForce>& forces) {
  // Each block sends the bodies it reports, with their forces; block 0 sorts them by id.
  BlockStep mine;
  std::vector<BodyForce> mineForces;
  for (std::size_t b = 0; b < bodies.size() && b < forces.size(); ++b) {
    if (!forces[b].reported) continue;
    mine.bodies.push_back(bodies[b]);
    mineForces.push_back(forces[b]);
  }
  Writer w;
  w.bytes = encodeStep(mine);
  for (const auto& f : mineForces) w.put(f);
  const int count = static_cast<int>(w.bytes.size());
  std::vector<int> counts(static_cast<std::size_t>(impl_->size)), offsets(counts.size());
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, impl_->world);
  std::vector<char> all;
  if (impl_->rank == 0) {
    int total = 0;
    for (std::size_t r = 0; r < counts.size(); ++r) {
      offsets[r] = total;
      total += counts[r];
    }
    all.resize(static_cast<std::size_t>(total));
  }
  MPI_Gatherv(w.bytes.data(), count, MPI_CHAR, all.data(), counts.data(), offsets.data(), MPI_CHAR,
              0, impl_->world);
  bodies.clear();
  forces.clear();
  if (impl_->rank != 0) return;
  std::vector<std::pair<RigidBody, BodyForce>> merged;
  for (std::size_t r = 0; r < counts.size(); ++r) {
    const std::vector<char> part(all.begin() + offsets[r], all.begin() + offsets[r] + counts[r]);
    BlockStep theirs;
    if (!decodeStep(part, theirs)) continue;  // same process image: cannot happen
    // The forces follow the encoded step: read them from its end.
    const std::size_t forceBytes = theirs.bodies.size() * sizeof(BodyForce);
    if (part.size() < forceBytes) continue;
    const char* p = part.data() + part.size() - forceBytes;
    for (auto& body : theirs.bodies) {
      BodyForce f;
      std::memcpy(&f, p, sizeof f);
      p += sizeof f;
      merged.emplace_back(std::move(body), f);
    }
  }
  std::sort(merged.begin(), merged.end(),
            [](const auto& a, const auto& b) { return a.first.id < b.first.id; });
  for (auto& [body, force] : merged) {
    bodies.push_back(std::move(body));
    forces.push_back(force);
  }
}

void JobBlock::stop() {
  if (impl_->stopped) return;
  impl_->stopped = true;
  MPI_Finalize();
}

}  // namespace vrflow::fluid
