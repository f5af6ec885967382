#pragma once

#include <sys/types.h>

#include <cstdint>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/ipc/join_contract.hpp"

namespace vrflow::run {

/// Starts `executable` as a module process: its own process group (Ctrl-C reaches only the
/// runtime, which stops modules in order), killed if the runtime dies, with the segment's
/// descriptor inherited and the given extra environment. `memoryLimitBytes` (0: none) caps the
/// process's data memory (RLIMIT_DATA: heap and private mappings, not the shared segment).
/// `outputFd` (-1: this process's) becomes its stdout and stderr (ModuleOutput::add()).
Result<pid_t> spawnModule(const std::string& executable, const std::vector<std::string>& args,
                          int inheritFd, const std::vector<std::string>& extraEnvironment,
                          uint64_t memoryLimitBytes = 0, int outputFd = -1);

/// Starts `executable` as `ranks` MPI ranks of one job through Open MPI's `mpirun` (the
/// environment variable VRFLOW_MPIRUN names another launcher; found on PATH otherwise), as
/// spawnModule does for one process: the returned pid is mpirun's, in its own process group,
/// killed if the runtime dies. mpirun closes inherited descriptors, so the ranks get the
/// segment of `contract` by its path (JoinContract::segmentPath = /proc/<runtime pid>/fd/<fd>)
/// instead (rank 0 opens it and joins as the module; the others are its workers), and
/// JoinContract::mpiRanks = ranks. The whole contract is exported to the ranks (`-x`).
/// `backingDir` (see MpiBackingFolder; empty: Open MPI's default, /dev/shm) receives the
/// shared-memory files of Open MPI's vader transport. With an `outputFd` (mpirun's stdout and
/// stderr), mpirun tags each line with its rank (--tag-output: "[JOB,RANK]<stdout>:TEXT").
Result<pid_t> spawnMpiModule(const std::string& executable, int ranks,
                             const ipc::JoinContract& contract, const std::string& backingDir,
                             uint64_t memoryLimitBytes = 0, int outputFd = -1);

/// Starts the modules of one MPI job (app::MpiJob), one per rank, as one `mpirun -np N` of
/// `executable` with N = slotIndices.size(), the options, launcher and segment path of
/// spawnMpiModule(). Rank r joins the run as the module of slot slotIndices[r]: the ranks get
/// JoinContract::moduleIndices = slotIndices (Module::init() takes the entry of its rank, from
/// OMPI_COMM_WORLD_RANK or PMIX_RANK) instead of the contract's moduleIndex and moduleId, and
/// no mpiRanks (every rank is a module, none a worker).
Result<pid_t> spawnMpiJob(const std::string& executable, const std::vector<int>& slotIndices,
                          const ipc::JoinContract& contract, const std::string& backingDir,
                          uint64_t memoryLimitBytes = 0, int outputFd = -1);

/// The folder of a runtime's MPI jobs' shared-memory files (Open MPI's vader segments, which
/// its ranks cannot unlink when they die with the runtime): /dev/shm/ompi-job.<runtime pid>.XXXXXX,
/// mode 0700, made on first use and removed with its contents on destruction.
class MpiBackingFolder {
 public:
  MpiBackingFolder() = default;
  ~MpiBackingFolder();
  MpiBackingFolder(const MpiBackingFolder&) = delete;
  MpiBackingFolder& operator=(const MpiBackingFolder&) = delete;
  /// The folder, made on the first call.
  Result<std::string> path();

 private:
  std::string path_;
};

/// Removes the MpiBackingFolder folders of this user whose runtime has died (kill -9 leaves
/// them), with the files in them.
void removeStaleMpiBackingFolders();

/// "exited with status 3" / "was killed by signal 11 (Segmentation fault)".
std::string describeWaitStatus(int status);

/// describeWaitStatus of an mpirun, which exits with 128 + N when one of its ranks was killed by
/// signal N: "exited with status 137 (an MPI rank was killed by signal 9 (Killed))".
std::string describeMpirunWaitStatus(int status);

}  // namespace vrflow::run
