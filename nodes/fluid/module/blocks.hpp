#pragma once

#include <memory>
#include <vector>

#include "vrflow/fluid/solver.hpp"

// The fluid module as several MPI blocks, rank 0 being the module vrflow talks to. Two ways to
// start them:
// - through mpirun (the usual one): the manifest's `mpi-ranks="blocks"` makes vrflow start the
//   module as `mpirun -np blocks vrflow-fluid`; rank 0 joins the run (it opens the run's shared
//   memory by VRFLOW_SEGMENT_PATH, since mpirun closes inherited descriptors), the other ranks
//   run as workers on MPI_COMM_WORLD;
// - without mpirun (VRFLOW_MPIRUN=none, or no Open MPI launcher): the module, started by vrflow
//   like any other, initialises MPI as a singleton and spawns `blocks - 1` copies of its own
//   executable with `--block-worker --watch NAME` (MPI_Comm_spawn; NAME: rank 0's WorkerWatch);
//   together they form one communicator.
// Each iteration rank 0 broadcasts the step (dt, bodies, what to report) and every rank steps its
// slab; forces and particles come back to rank 0 through the solver's collective calls.
// A failure ends the whole group, never leaves rank 0 waiting: blocks whose step failed agree
// (a barrier bounded to 5 s) that they all failed it, and stop cleanly with rank 0 reporting it;
// a block that failed alone aborts the MPI job (MPI_Abort; rank 0 returns the error and exits
// without MPI_Finalize). A dead rank ends an mpirun job; spawned workers are watched by rank 0
// (worker_watch.hpp), which Open MPI does not tell when one dies.

namespace vrflow::fluid {

/// What rank 0 asks of every block for one iteration.
struct BlockStep {
  bool stop = false;
  bool queryOnly = false;  ///< no step: only the queries below (the final state)
  double dt = 0.0;
  std::vector<RigidBody> bodies;
  std::vector<PointMass> points;
  bool gatherParticles = false;
  bool stats = false;
};

/// What one step gave back on this block (particles, volume, speed only when asked).
struct BlockResult {
  std::vector<BodyForce> forces;
  std::vector<float> particles;  ///< every block's, on rank 0
  double volume = 0.0;
  double maxSpeed = 0.0;
};

/// Runs one step on this block, with the collective queries the step asks for.
Result<BlockResult> stepBlock(FluidSolver& solver, const BlockStep& step);

/// Rank 0's side: spawns the workers and drives them.
class BlockGroup {
 public:
  /// Starts MPI and `blocks - 1` workers running `executable --block-worker`; sends them the
  /// settings and the liquid box. The solver returned is rank 0's block.
  static Result<std::unique_ptr<BlockGroup>> start(const char* executable, int blocks,
                                                   const FluidSettings& settings,
                                                   const msg::Aabb& fill);
  ~BlockGroup();
  /// Runs one step on every block (collective). After an error the workers are gone or going:
  /// return from the module with the error.
  Result<BlockResult> step(const BlockStep& step);
  /// Tells the workers to stop and finalises MPI.
  void stop();
  FluidSolver& solver();

 private:
  struct Impl;
  explicit BlockGroup(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// A worker's main (the executable run with --block-worker).
int runBlockWorker(int argc, char** argv);

/// This process's rank when vrflow started the module through mpirun (VRFLOW_MPI_RANKS set),
/// else -1.
int mpirunRank();

/// The main of ranks 1 ... N-1 of a module started through mpirun.
int runRankWorker(int argc, char** argv);

}  // namespace vrflow::fluid
