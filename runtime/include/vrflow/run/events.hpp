#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"

// The machine-readable event stream of a run (docs/events.md): one JSON object per line, each
// with "event" (its kind) and "time" (seconds since the stream opened). `vrflow run --events`,
// `vrflow launch --events`, the editor and the tests read it; people read the progress line.
namespace vrflow::run {

struct RunOutcome;

/// Writes a run's events as JSON lines. Thread-safe: each line is written whole.
class EventStream {
 public:
  /// Receives each line, without its newline.
  using Writer = std::function<void(const std::string& line)>;

  /// A stream that hands each line to `writer` (empty: to none but the tee); `withStats`: false
  /// drops the stats events (a daemon under the launcher, whose statistics travel on their own
  /// control lines).
  explicit EventStream(Writer writer, bool withStats = true);
  /// `vrflow run --events TARGET`: "-" is standard output (dup'ed first: the caller may then
  /// point descriptor 1 elsewhere), anything else a file, created or truncated.
  static Result<std::unique_ptr<EventStream>> open(const std::string& target);
  ~EventStream();
  EventStream(const EventStream&) = delete;
  EventStream& operator=(const EventStream&) = delete;

  /// Also hands each line to `tee` (the run's registration, docs/operations.md), in order and
  /// one at a time; set before the first event.
  void tee(Writer tee);

  /// "started": the application, its hosts and modules, before the modules start.
  void started(const app::Application& application);
  /// "stats": a snapshot of counters (the JSON object of the supervisor's statistics:
  /// modules, connections, filters, and links under a launcher) with "host" added when given.
  void stats(const std::string& snapshotJson, const std::string& host = {});
  /// "warning": something a person should know that does not fail the run.
  void warning(const std::string& text, const std::string& host = {});
  /// "module_exit": a module's process ended ("status 0", "signal 9", ...), with why when known.
  void moduleExit(const std::string& module, const std::string& host, const std::string& exit,
                  const std::string& cause);
  /// "end": the run is over, with its exit status, outcome word and error (empty on success).
  void end(const RunOutcome& outcome);
  /// Writes a line another stream made (a daemon's, relayed by the launcher), adding "host" and
  /// putting "time" on this stream's clock; its "started" and "end" are left out (the merged
  /// stream has its own).
  void relay(const std::string& line, const std::string& host);

 private:
  void write(const std::string& line);
  double elapsed() const;

  Writer writer_;
  Writer tee_;
  bool withStats_ = true;
  int fd_ = -1;  ///< owned by open()'s streams
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace vrflow::run
