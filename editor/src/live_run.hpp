#pragma once

// What the editor knows of a run, read from its machine-readable event stream
// (docs/events.md): per module, connection, link between hosts and host, the latest figures and
// rates between the last two `stats` events, and how the run ended. The run controller feeds it
// lines; the canvas overlay, the hosts panel and the run table show it.

#include <QByteArray>
#include <QObject>
#include <cstdint>
#include <deque>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace vrflow::editor::gui {

/// One module of the run.
struct ModuleLive {
  std::string id;
  std::string type;   ///< "package/type"
  std::string host;   ///< host id
  std::string state;  ///< the stream's state ("waiting", "computing", ...); "exited" at its end
  uint64_t iterations = 0;
  double rate = 0;       ///< iterations/s between the last two `stats`
  double waitShare = 0;  ///< wait / (wait + compute) over that interval, 0..1
  double cpu = 0;        ///< CPU over that interval, in cores (1 = one core busy)
  double rssMiB = 0;
  std::deque<double> history;  ///< `rate` at each `stats`, the last minute of them
  std::string exit;            ///< "status N" or "signal N" once its process ended
  std::string failure;         ///< why the run failed here (empty when it did not)
};

/// One connection of the expanded network (`from`/`to` as "node.port").
struct ConnectionLive {
  std::string from;
  std::string to;
  uint64_t length = 0;    ///< messages queued now
  uint64_t capacity = 0;  ///< queue capacity (0: unbounded)
  double fill = 0;        ///< length / capacity, 0..1 (0 when unbounded)
  double messagesPerSecond = 0;
  double mibPerSecond = 0;
  uint64_t messages = 0;  ///< totals since the start
  uint64_t bytes = 0;
  uint64_t dropped = 0;
};

/// Traffic from one host to another (launch only), counted by the sending host.
struct LinkLive {
  std::string from;  ///< host id
  std::string to;    ///< host id
  double messagesPerSecond = 0;
  double mibPerSecond = 0;
  uint64_t messages = 0;
  uint64_t bytes = 0;
};

/// One host of the run.
struct HostLive {
  std::string id;
  std::string address;
  double cpu = 0;     ///< its modules' CPU, in cores
  double rssMiB = 0;  ///< its modules' resident memory
  bool lost = false;  ///< its daemon or connection was lost
  std::string cause;  ///< why it failed or was lost (empty when fine)
  int modules = 0;    ///< how many modules of the run it holds
};

/// Everything known of one run.
struct LiveRun {
  enum class Phase { None, Running, Ended };
  Phase phase = Phase::None;
  std::string application;
  std::string file;
  double time = 0;  ///< seconds of the stream at its last event
  std::map<std::string, ModuleLive> modules;
  std::vector<ConnectionLive> connections;
  std::vector<LinkLive> links;
  std::vector<HostLive> hosts;  ///< in the order of the `started` event
  std::vector<std::string> warnings;
  // From the `end` event.
  int exitCode = -1;
  std::string status;  ///< "ok", "failed", "deadlock", "stalled", "timeout", "interrupted", ...
  std::string error;   ///< one line; empty on success

  /// One line for the status bar: "Running: 12.3 s", "Finished: 1000 iterations in 2.1 s",
  /// "Failed (stalled): <error>", ...
  std::string summary() const;
  HostLive* host(const std::string& id);
  const HostLive* host(const std::string& id) const;
  /// The connection from `from` to `to` ("node.port" of the expanded network), or nullptr.
  const ConnectionLive* connection(const std::string& from, const std::string& to) const;
  /// The link from host `from` to host `to`, or nullptr.
  const LinkLive* link(const std::string& from, const std::string& to) const;
};

/// Reads event lines into a LiveRun.
class LiveRunModel : public QObject {
  Q_OBJECT

 public:
  explicit LiveRunModel(QObject* parent = nullptr) : QObject(parent) {}

  /// Forgets the run (a new one starts).
  void reset();
  /// Reads one line of the stream (without its newline). Lines that are not JSON objects or not
  /// events are counted in badLines() and otherwise ignored.
  void handleLine(const QByteArray& line);
  const LiveRun& run() const { return run_; }
  int badLines() const { return badLines_; }

 Q_SIGNALS:
  /// After each event that changed run().
  void changed();
  /// After the `end` event.
  void ended();

 private:
  LiveRun run_;
  double lastStatsTime_ = -1;  ///< time of the previous `stats` (per host under a launch)
  std::map<std::string, double> lastStatsTimeOfHost_;
  /// A module's totals at the previous `stats` (rates need two).
  struct Totals {
    uint64_t compute = 0, wait = 0, cpu = 0;
  };
  std::map<std::string, Totals> previous_;
  /// A connection's or link's counters at its previous `stats` (by "from\nto").
  struct Counters {
    double time = -1;
    uint64_t messages = 0, bytes = 0;
  };
  std::map<std::string, Counters> previousTraffic_;
  int badLines_ = 0;

  void readStats(const nlohmann::json& event);
  void readConnections(const nlohmann::json& event);
  void readLinks(const nlohmann::json& event, const std::string& host);
  /// Sets `counted`'s rates from its totals and those at its previous `stats` (under `key`).
  template <typename T>
  void traffic(const std::string& key, T& counted);
  void markHost(const std::string& host, const std::string& cause, bool lost);
  void sumHosts();
};

}  // namespace vrflow::editor::gui
