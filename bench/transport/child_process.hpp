#pragma once

#include <sys/types.h>

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"

namespace vrflow::bench {

/// A process the benchmark started. It dies with us (PR_SET_PDEATHSIG), and dropping the handle
/// terminates and reaps it, so no run leaves a process behind, also when it fails.
class ChildProcess {
 public:
  /// Forks; the child runs body and exits with its return value without unwinding our stack.
  /// The caller must be single-threaded (only the calling thread survives a fork).
  static Result<ChildProcess> fork(const std::function<int()>& body);

  /// Runs argv (argv[0] must be a path) with stdin from /dev/null and stdout piped to us;
  /// stderr is shared with ours so its messages reach the user.
  static Result<ChildProcess> spawn(const std::vector<std::string>& argv);

  ChildProcess(ChildProcess&& other) noexcept;
  ChildProcess& operator=(ChildProcess&& other) noexcept;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess();

  /// True while the process has not exited; reaps it (once) when it has.
  bool running();

  /// The next line the child wrote on stdout, or nothing at end of file; an error when no line
  /// came within the timeout. Only for spawned processes.
  Result<std::optional<std::string>> readLine(std::chrono::milliseconds timeout);

  /// Waits for the exit, terminating the process if it outlives the timeout; returns the wait
  /// status (see describeExit).
  Result<int> wait(std::chrono::milliseconds timeout);

  /// Stops the process now (SIGTERM, then SIGKILL after a grace period) and reaps it.
  void terminate();

  /// How the process ended ("exited with status 0", ...), or "is running".
  std::string exitDescription();

  /// "exited with status N" / "killed by signal S" for a wait status.
  static std::string describeExit(int waitStatus);

 private:
  ChildProcess(pid_t pid, int stdoutFd) : pid_(pid), stdoutFd_(stdoutFd) {}
  void release();

  pid_t pid_ = -1;
  int stdoutFd_ = -1;
  std::optional<int> waitStatus_;
  std::string pending_;  // stdout bytes read but not yet returned as a line
};

/// Full path of an executable found in $PATH, or nothing.
std::optional<std::string> findInPath(const std::string& name);

/// Number of threads of this process (from /proc/self/status); 0 when unknown.
int threadCount();

}  // namespace vrflow::bench
