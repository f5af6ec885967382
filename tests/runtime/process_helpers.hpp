#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace vrflow::testing {

/// What a finished command printed and how it ended.
struct CommandResult {
  int exitCode = -1;  ///< exit status, or 128 + signal
  std::string out, err;
};

/// Runs a command to completion (killed after timeoutSeconds), capturing stdout and stderr.
/// If `signalAfterSeconds` > 0, sends `signal` to it after that delay.
CommandResult runCommand(const std::vector<std::string>& argv, double timeoutSeconds = 60,
                         double signalAfterSeconds = 0, int signal = 0);

/// `vrflow` with the test packages on the search path.
CommandResult runVrflow(std::vector<std::string> args, double timeoutSeconds = 60,
                        double signalAfterSeconds = 0, int signal = 0);

/// Processes left behind by the commands this test ran (reparented to this process, which is a
/// child subreaper), killed and reaped; their command lines are returned.
std::vector<std::string> leftoverProcesses();

/// A TCP port of `address` (IPv4) where nobody listens now: bound to port 0, read, closed.
int unusedPort(const std::string& address = "127.0.0.1");

/// One process as /proc/PID/stat shows it.
struct ProcessInfo {
  pid_t pid = 0;
  pid_t parent = 0;
  char state = 0;    ///< 'R', 'S', 'Z' (ended, not yet reaped), ...
  std::string name;  ///< the command name (comm), without its parentheses
};

/// Every process of the machine, from /proc (those that end while it reads are left out).
std::vector<ProcessInfo> processTable();

/// Entries of /dev/shm whose name mentions vrflow.
std::vector<std::string> vrflowShmEntries();

/// A fresh folder under /tmp, removed with its contents on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  /// Writes `text` to a file in this folder and returns its path.
  std::string write(const std::string& name, const std::string& text) const;

 private:
  std::string path_;
};

std::string readFile(const std::string& path);
std::vector<std::string> readLines(const std::string& path);
/// The rows of a CSV file after its header line, split at commas (no quoting).
std::vector<std::vector<std::string>> readCsvRows(const std::string& path);
std::string binDir();
std::string sourceDir();

}  // namespace vrflow::testing
