#pragma once

#include <memory>
#include <string>
#include <vector>

#include "vrflow/fluid/solver.hpp"

// The fluid module as several MPI blocks, two ways, both started by vrflow (only the runtime
// starts processes):
// - BlockGroup, one module of `blocks` ranks: the manifest's `mpi-ranks="blocks"` makes vrflow
//   start the module as `mpirun -np blocks vrflow-fluid`; rank 0 joins the run as the module (it
//   opens the run's shared memory by VRFLOW_SEGMENT_PATH, since mpirun closes inherited
//   descriptors), the other ranks run as its workers on MPI_COMM_WORLD. Each iteration rank 0
//   broadcasts the step (dt, bodies, what to report) and every rank steps its slab; forces and
//   particles come back to rank 0 through the solver's collective calls.
// - JobBlock, one module per block: the modules of one MPI job (the manifest's `mpi-job="job"`,
//   the composite fluid_blocks), which vrflow starts as one mpirun, one rank each.
// A failure ends the whole group, never leaves a block waiting: blocks whose step failed agree
// (a barrier bounded to 5 s) that they all failed it, and stop cleanly with the error reported;
// a block that failed alone aborts the MPI job (MPI_Abort; BlockGroup's rank 0 returns the error
// and exits without MPI_Finalize). A dead rank ends its mpirun, and so the job.

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

/// Rank 0's side of a module started as `blocks` ranks through mpirun: drives the workers.
class BlockGroup {
 public:
  /// Starts MPI on rank 0 of the module's mpirun job and sends the workers (runRankWorker) the
  /// settings and the liquid box. The solver returned is rank 0's block. An error when this
  /// process is not rank 0 of such a job (VRFLOW_MPI_RANKS unset: not started by vrflow so).
  static Result<std::unique_ptr<BlockGroup>> start(int blocks, const FluidSettings& settings,
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

/// One block of an MPI job of fluid modules: every module of the job (the same `job` parameter;
/// the manifest's `mpi-job="job"` makes vrflow start them as one mpirun, one rank each) is a
/// module with its own ports, fed the objects near its slab (by a route filter, say) and sending
/// its own forces and particles; a gather filter joins them. Ranks are peers: no rank drives
/// the others. The same failure handling as BlockGroup: blocks failing together end cleanly,
/// a block failing alone aborts the job.
class JobBlock {
 public:
  /// Initialises MPI (a job of one module runs as an MPI singleton), builds this rank's block of
  /// the solver with local bodies (FluidSolver::setLocalBodies) and fills it.
  static Result<std::unique_ptr<JobBlock>> start(const std::string& job,
                                                 const FluidSettings& settings,
                                                 const msg::Aabb& fill);
  ~JobBlock();
  int rank() const;
  int size() const;
  FluidSolver& solver();
  /// This block's slab of z-planes with the grid's extent along x and y, widened by
  /// `marginCells` cells on every side (kLocalBodyMargin: the box it needs the objects of).
  msg::Aabb slab(int marginCells) const;
  /// Whether every block goes on (collective): false on any block stops them all together.
  bool agree(bool mine);
  /// Block 0's `value`, on every block (collective).
  bool fromFirst(bool value);
  /// Runs one step on this block. A failure on every block returns the error on each (they
  /// finalise MPI together at exit, once each has printed it); a block that fails alone aborts
  /// the job (MPI_Abort) after printing its error.
  Result<BlockResult> step(const BlockStep& step);
  /// The rigid bodies and their forces over every block, each body once (from the block that
  /// reports it), in id order on block 0; `bodies` and `forces` are this block's (forces: the
  /// step's, bodies first). Collective; other blocks get nothing.
  void gatherBodies(std::vector<RigidBody>& bodies, std::vector<BodyForce>& forces);
  /// Finalises MPI (every block together, after `agree` said stop).
  void stop();

 private:
  struct Impl;
  explicit JobBlock(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// This process's rank when vrflow started the module through mpirun (VRFLOW_MPI_RANKS set),
/// else -1.
int mpirunRank();

/// The main of ranks 1 ... N-1 of a module started through mpirun (BlockGroup's workers).
int runRankWorker(int argc, char** argv);

}  // namespace vrflow::fluid
