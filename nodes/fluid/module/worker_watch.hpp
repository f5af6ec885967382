#pragma once

#include <sys/types.h>

#include <memory>
#include <string>
#include <thread>

// Rank 0's watch over the workers it spawns itself (VRFLOW_MPIRUN=none). Open MPI 4 does not
// tell a singleton that a process it spawned died: rank 0 would wait for it, in MPI_Comm_spawn
// or in a collective call, until vrflow's --timeout. So each worker, first thing, connects to a
// unix socket of rank 0 (abstract name: no file) and keeps the connection until it exits; a
// thread of rank 0 sees a connection close before the watch is released, says which block died,
// and ends the module, so that vrflow reports the module's failure at once (the singleton's
// orted, seeing the module gone, ends the other workers).

namespace vrflow::fluid {

/// Ends this process with a clear message if a watched worker ends before release.
class WorkerWatch {
 public:
  /// Listens for `workers` workers (blocks 1 ... workers), which must all connect within 30 s.
  /// Returns null (after a warning) if no socket can be made: the module then runs unwatched.
  static std::unique_ptr<WorkerWatch> start(int workers);
  /// Releases the watch: the workers may end from now on (they were told to stop).
  ~WorkerWatch();
  WorkerWatch(const WorkerWatch&) = delete;
  WorkerWatch& operator=(const WorkerWatch&) = delete;
  /// The name the workers connect to (their `--watch` argument).
  const std::string& name() const { return name_; }

  /// A worker's side: connects to the watch `name`, before MPI_Init. The connection stays open
  /// until the process ends. Returns the socket, or -1 after printing why.
  static int join(const std::string& name);
  /// A worker's side: tells the watch which block this process is (for rank 0's message).
  static void tellBlock(int socket, int block);

 private:
  WorkerWatch(int workers, int listenFd, int releaseFd, std::string name);
  void watch();

  int workers_ = 0;
  int listenFd_ = -1;
  int releaseFd_ = -1;
  std::string name_;
  std::thread thread_;
};

}  // namespace vrflow::fluid
