#pragma once

#include <sys/types.h>

#include <memory>
#include <thread>
#include <vector>

// Rank 0's watch over the workers it spawned itself (VRFLOW_MPIRUN=none). Open MPI 4 does not
// tell a singleton that a process it spawned died: rank 0 would wait for it in a collective call
// until vrflow's --timeout. A thread polls a pidfd per worker; when one ends before the watch is
// released, it says which block died and ends the module, so vrflow reports the module's failure
// at once (and the singleton's orted, seeing the module gone, ends the other workers).

namespace vrflow::fluid {

/// Ends this process with a clear message if a watched worker ends before release.
class WorkerWatch {
 public:
  /// Watches `pids` (those of blocks 1 ... N-1, in order; N = pids.size() + 1). Returns null
  /// (after a warning) where the kernel has no pidfd: the module then runs unwatched.
  static std::unique_ptr<WorkerWatch> start(const std::vector<pid_t>& pids);
  /// Releases the watch: the workers may end from now on (they were told to stop).
  ~WorkerWatch();
  WorkerWatch(const WorkerWatch&) = delete;
  WorkerWatch& operator=(const WorkerWatch&) = delete;

 private:
  WorkerWatch(std::vector<int> pidfds, std::vector<pid_t> pids, int releaseFd);
  void watch();

  std::vector<int> pidfds_;
  std::vector<pid_t> pids_;
  int releaseFd_ = -1;
  std::thread thread_;
};

}  // namespace vrflow::fluid
