#pragma once

#include <sys/types.h>

#include <cstdint>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"

namespace vrflow::run {

/// Starts `executable` as a module process: its own process group (Ctrl-C reaches only the
/// runtime, which stops modules in order), killed if the runtime dies, with the segment's
/// descriptor inherited and the given extra environment. `memoryLimitBytes` (0: none) caps the
/// process's data memory (RLIMIT_DATA: heap and private mappings, not the shared segment).
Result<pid_t> spawnModule(const std::string& executable, const std::vector<std::string>& args,
                          int inheritFd, const std::vector<std::string>& extraEnvironment,
                          uint64_t memoryLimitBytes = 0);

/// Starts `executable` as `ranks` MPI ranks of one job through Open MPI's `mpirun` (the
/// environment variable VRFLOW_MPIRUN names another launcher; found on PATH otherwise), as
/// spawnModule does for one process: the returned pid is mpirun's, in its own process group,
/// killed if the runtime dies. mpirun closes inherited descriptors, so the ranks get the
/// segment as VRFLOW_SEGMENT_PATH=/proc/<runtime pid>/fd/<fd> instead (rank 0 opens it and
/// joins as the module; the others are its workers), and VRFLOW_MPI_RANKS=ranks. Every
/// VRFLOW_* variable of `extraEnvironment` is exported to the ranks (`-x`).
/// `backingDir` (see MpiBackingFolder; empty: Open MPI's default, /dev/shm) receives the
/// shared-memory files of Open MPI's vader transport.
Result<pid_t> spawnMpiModule(const std::string& executable, int ranks, int segmentFd,
                             const std::vector<std::string>& extraEnvironment,
                             const std::string& backingDir, uint64_t memoryLimitBytes = 0);

/// Starts the modules of one MPI job (app::MpiJob), one per rank, as one `mpirun -np N` of
/// `executable` with N = slotIndices.size(), the options, launcher and segment path of
/// spawnMpiModule(). Rank r joins the run as the module of slot slotIndices[r]: the ranks get
/// VRFLOW_MODULE_INDICES="i0,i1,..." (Module::init() takes the entry of its rank, from
/// OMPI_COMM_WORLD_RANK or PMIX_RANK) instead of VRFLOW_MODULE_INDEX and VRFLOW_MODULE_ID, and
/// no VRFLOW_MPI_RANKS (every rank is a module, none a worker).
Result<pid_t> spawnMpiJob(const std::string& executable, const std::vector<int>& slotIndices,
                          int segmentFd, const std::vector<std::string>& extraEnvironment,
                          const std::string& backingDir, uint64_t memoryLimitBytes = 0);

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
