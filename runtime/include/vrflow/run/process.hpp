#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <sys/types.h>

#include <cstdint>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"

// The one fork/exec of vrflow: every process the runtime or the launcher starts (modules,
// mpirun, daemons, ssh) goes through spawnProcess().
namespace vrflow::run {

/// How to start a process.
struct ProcessSettings {
  /// argv[0] is a path, or a bare name looked up on $PATH; the rest are its arguments.
  std::vector<std::string> argv;
  /// Its whole environment, "NAME=VALUE" each (environmentWith() adds to this process's).
  std::vector<std::string> environment;
  int stdinFd = -1;    ///< becomes its standard input; -1: this process's
  int stdoutFd = -1;   ///< becomes its standard output; -1: this process's
  int stderrFd = -1;   ///< becomes its standard error; -1: this process's
  int inheritFd = -1;  ///< a close-on-exec descriptor it keeps open; -1: none
  /// Caps its data memory (RLIMIT_DATA: heap and private mappings, not shared segments); 0: none.
  uint64_t memoryLimitBytes = 0;
};

/// Starts a process in its own process group (Ctrl-C reaches only its parent, which stops it in
/// order), killed if this process dies (PR_SET_PDEATHSIG), with every signal unblocked and
/// SIGPIPE at its default; of this process's descriptors it keeps only its standard ones and
/// `inheritFd`. An executable that cannot be found or run is an error naming it,
/// before anything starts.
Result<pid_t> spawnProcess(const ProcessSettings& settings);

/// This process's environment with `extra` ("NAME=VALUE") added, replacing variables of the
/// same names.
std::vector<std::string> environmentWith(const std::vector<std::string>& extra);

}  // namespace vrflow::run
