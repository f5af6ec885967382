#pragma once

// Capture of the module processes' output: one pipe per process (its stdout and stderr), read on
// a thread of its own so that a module that prints much never stalls the supervisor or the
// message path. Private to runtime/src/run.
#include <atomic>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/run/module_logs.hpp"

namespace vrflow::run::detail {

/// Reads the pipes of the module processes and hands their lines to a ModuleLogs. Memory is
/// bounded: a line longer than kMaxLineBytes is cut there; the pipes are read as fast as the
/// logs take the lines, so a module that prints faster waits on its own writes.
class ModuleOutput {
 public:
  static constexpr std::size_t kMaxLineBytes = 64 * 1024;

  explicit ModuleOutput(ModuleLogs& logs) : logs_(logs) {}
  ~ModuleOutput();
  ModuleOutput(const ModuleOutput&) = delete;
  ModuleOutput& operator=(const ModuleOutput&) = delete;

  /// A pipe for one process, whose lines go to module `modules[0]` (ModuleLogs indices). With
  /// `mpiTagged` the process is an mpirun started with --tag-output: a line of rank r goes to
  /// `modules[r]` when there is one per rank (an MPI job), else to `modules[0]` with its rank
  /// named. Returns the pipe's write end (close-on-exec): the process gets it as its stdout and
  /// stderr, and the caller closes it once the process started.
  Result<int> add(std::vector<std::size_t> modules, bool mpiTagged);
  /// Reads until every process (and whatever inherited its pipe) closed it, at most `seconds`,
  /// hands over the last partial lines, and stops the reading thread.
  void finish(double seconds);

 private:
  struct Source {
    int fd = -1;
    std::vector<std::size_t> modules;
    bool mpiTagged = false;
    std::string partial;  ///< the start of a line not yet ended
  };
  void readLoop();
  /// Reads what `source` holds now; false at its end (then closed).
  bool drain(Source& source);
  void split(Source& source, bool atEnd);
  void deliver(const Source& source, std::string_view text);

  ModuleLogs& logs_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<Source>> sources_;  ///< guarded by mutex_; each owned by the thread
  std::atomic<bool> stopping_{false};
  std::atomic<long long> deadlineNs_{0};
  std::thread thread_;
};

}  // namespace vrflow::run::detail
