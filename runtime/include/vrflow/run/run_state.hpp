#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <cstdint>
#include <memory>
#include <string>

// The live state of a run as its event stream (docs/events.md) tells it: what the registry keeps
// of a run (docs/operations.md) and what `vrflow monitor` shows.
namespace vrflow::run {

/// The state of a run, kept up to date from its event lines: the application, each host's last
/// two statistics snapshots, the last warnings and the end. Bounded whatever the run's length.
class RunState {
 public:
  /// At most this many warnings are kept (the latest).
  static constexpr std::size_t kMaxWarnings = 20;

  RunState();
  ~RunState();
  RunState(const RunState& other);
  RunState& operator=(const RunState& other);
  RunState(RunState&&) noexcept;
  RunState& operator=(RunState&&) noexcept;

  /// The state saved by toJson(); an empty state if `text` is not one.
  static RunState fromJson(const std::string& text);

  /// Takes one event line; true when the statistics changed (a new snapshot). Lines that are
  /// not events are ignored.
  bool take(const std::string& line);
  /// Marks the run as ended without an "end" event (a run found dead: "lost").
  void endAs(const std::string& status, const std::string& error);

  /// {"application", "file", "hosts": [{"host", "now", "before"}], "warnings": [...],
  ///  "end": {"exit_code", "status", "error"} or null}: what renderLaunch() shows.
  std::string toJson() const;
  bool ended() const;
  /// The end's status word (ok, failed, interrupted, lost, ...); empty while running.
  std::string endStatus() const;
  /// "run ended: STATUS (exit N)[: ERROR]"; empty while running.
  std::string endLine() const;
  /// The fewest iterations done by a module of any host (the outer iterations when no module
  /// repeats); 0 before the first statistics.
  uint64_t iterations() const;
  /// Iterations per second of that module between the last two snapshots; 0 when unknown.
  double rate() const;

 private:
  struct Data;
  std::unique_ptr<Data> data_;
};

}  // namespace vrflow::run
