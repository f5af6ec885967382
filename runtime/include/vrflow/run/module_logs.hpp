#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <cstdint>
#include <cstdio>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/base/result.hpp"

namespace vrflow::run {

/// What a module printed ends here (docs/logs.md): each line on stderr as "[module@host] line"
/// (the prefix in one colour per module on a terminal), appended to <logDir>/<module>.log as
/// written, handed to a forwarder (vrflow-daemon: the launcher), and the last lines of each
/// module kept for its failure message. Thread-safe. Used by the supervisor (its modules' pipes,
/// ModuleOutput) and by the launcher (the lines its daemons forward).
class ModuleLogs {
 public:
  /// How many of each module's last lines are kept (lastLines()).
  static constexpr std::size_t kTailLines = 10;
  /// A kept line is cut after this many bytes.
  static constexpr std::size_t kTailLineBytes = 400;

  struct Settings {
    std::string logDir;   ///< <logDir>/<module>.log per module; empty: no files
    bool echo = true;     ///< print the lines on stderr with their prefix
    bool colour = false;  ///< colour the prefixes (see colourOnTerminal())
    /// Also hands each line (module id, text) here, from the thread that read it; empty: none.
    std::function<void(const std::string& module, std::string_view text)> forward;
  };

  explicit ModuleLogs(Settings settings);
  ~ModuleLogs();
  ModuleLogs(const ModuleLogs&) = delete;
  ModuleLogs& operator=(const ModuleLogs&) = delete;

  /// Adds module `id` of `host` (again: its index) and opens its log file (appending); an error
  /// naming the file when it cannot be written. Returns its index for line().
  Result<std::size_t> add(const std::string& id, const std::string& host);
  /// The index of module `id`, or -1 when it was not added.
  long find(const std::string& id) const;
  /// One line of module `module` (without its newline); `rank` >= 0 names the MPI rank that
  /// printed it in the terminal prefix ("[module@host rank 2]").
  void line(std::size_t module, std::string_view text, int rank = -1);
  /// A note of the runtime about module `module` ("12 lines dropped"): on stderr with the
  /// module's prefix and in its log file, marked "vrflow: "; not forwarded.
  void note(std::size_t module, std::string_view text);
  /// Writes what line() and note() gathered to stderr and the log files.
  void flush();

  /// <logDir>/<module>.log of module `id`; empty without a log folder or such a module.
  std::string logFile(const std::string& id) const;
  /// The last lines of module `id` (at most kTailLines, oldest first).
  std::vector<std::string> lastLines(const std::string& id) const;

  /// True when stderr is a terminal and NO_COLOR is not set (https://no-color.org).
  static bool colourOnTerminal();

 private:
  struct Module {
    std::string id, host, prefix, path;
    std::FILE* file = nullptr;
    std::deque<std::string> tail;
  };
  void append(Module& module, std::string_view text, const std::string& prefix);

  Settings settings_;
  mutable std::mutex mutex_;
  std::vector<Module> modules_;
  std::string pending_;  ///< what flush() writes on stderr
};

/// The note for `count` lines of a module that its daemon did not forward to the launcher
/// (over the rate of the control channel): "N lines dropped (...)".
std::string droppedNote(uint64_t count);

}  // namespace vrflow::run
