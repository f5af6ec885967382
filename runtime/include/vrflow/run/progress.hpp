#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

// What `vrflow run` and `vrflow launch` show people while an application runs: a live line on a
// terminal, one summary line at the end otherwise (docs/report.md, "Progress"). Programs read
// the event stream instead (docs/events.md).
namespace vrflow::run {

/// How a run shows its progress on stderr.
enum class ProgressMode {
  Off,      ///< nothing (--no-progress, a daemon under the launcher)
  Summary,  ///< one line at the end: iterations, seconds, iterations/s, status
  Live,     ///< a line redrawn about once a second (a terminal), the summary line at the end
};

/// One module's iterations: done so far, and how many it runs for the run's -n (0: no -n).
struct ModuleProgress {
  uint64_t done = 0;
  uint64_t target = 0;
};

/// The run's iterations done: with -n (`outer` > 0), the least share of its target any module
/// has done, in outer iterations (a module behind a repeat of k runs k per outer one); without
/// -n, the fewest iterations of any module. 0 for no module.
uint64_t outerIterationsDone(const std::vector<ModuleProgress>& modules, uint64_t outer);

/// The progress of one run. Used from one thread; printAboveProgress() may be called from any.
class ProgressLine {
 public:
  /// `outer`: the run's -n (0: none). The clock of its rate and seconds starts here.
  ProgressLine(ProgressMode mode, uint64_t outer);
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;
  ~ProgressLine();

  /// Live: true when update() would redraw (a second since the last time), to skip counting.
  bool due() const;
  /// Live: redraws the line with `done` iterations, at most once a second.
  void update(uint64_t done);
  /// Ends the progress: the summary line with `done` iterations and `status` (it replaces the
  /// live line on a terminal). Nothing after.
  void finish(uint64_t done, std::string_view status);

 private:
  std::string liveText(uint64_t done, double seconds);

  using Clock = std::chrono::steady_clock;
  ProgressMode mode_;
  uint64_t outer_;
  Clock::time_point start_, lastDraw_;
  uint64_t lastDone_ = 0;
  double rate_ = 0;  ///< iterations/s, smoothed over the redraws
  bool finished_ = false;
};

/// Prints `line` and a newline on stderr above the live progress line when one shows (erased
/// with "\r\033[K", then redrawn below it), else just prints it: how other output (modules' log
/// lines) shares a terminal with the progress line. Safe from any thread.
void printAboveProgress(std::string_view line);

}  // namespace vrflow::run
