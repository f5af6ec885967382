#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <string>
#include <string_view>

#include "vrflow/base/result.hpp"

// The runtime's own lines (the supervisor's, the launcher's, the daemon's warnings and errors),
// as opposed to what modules print (module_output.hpp): each gets a level and a time, on stderr
// and in <log folder>/vrflow.log (docs/logs.md). spdlog does the work; it stays out of this
// header, so that nothing that includes it depends on spdlog.
namespace vrflow::run {

/// How much the runtime says, from most to least: trace, debug, info, warn, error, off.
enum class LogLevel { Trace, Debug, Info, Warn, Error, Off };

/// The level of a `--log-level` word (trace, debug, info, warn, error, off); an error naming the
/// words otherwise.
Result<LogLevel> parseLogLevel(std::string_view word);

/// Sets the runtime's lines of this process: those at `level` and above go to stderr
/// ("HH:MM:SS.mmm LEVEL text", the level coloured on a terminal unless NO_COLOR is set) and,
/// when `logDir` is not empty, to `logDir`/vrflow.log ("YYYY-mm-dd HH:MM:SS.mmm LEVEL [pid]
/// text", flushed line by line). Without a call, lines at info and above go to stderr only.
Status setupLogging(LogLevel level, const std::string& logDir);

/// Flushes and closes vrflow.log (the lines after it go to stderr only).
void shutdownLogging();

/// Makes `dir` (mode 0700, with its missing parents) when it does not exist; an error saying
/// why when it is not a folder this process may write in.
Status prepareLogDirectory(const std::string& dir);

/// A runtime line at each level (text as written: "vrflow: warning: ...").
void logTrace(const std::string& text);
void logDebug(const std::string& text);
void logInfo(const std::string& text);
void logWarning(const std::string& text);
void logError(const std::string& text);

}  // namespace vrflow::run
