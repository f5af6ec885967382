#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/ipc/control.hpp"
#include "vrflow/ipc/module_slot_daemon.hpp"
#include "vrflow/ipc/segment.hpp"
#include "vrflow/net/transport.hpp"

namespace vrflow::daemon {

/// Settings of a host's daemon (defaults suit a desktop run).
struct DaemonOptions {
  std::size_t segmentBytes = std::size_t{1} << 30;  ///< sparse: only touched pages cost memory
  uint64_t iterationLimit = 0;                      ///< per module; 0 = no limit
  /// Per module id, replaces iterationLimit (multi-rate: see app::iterationRates).
  std::map<std::string, uint64_t, std::less<>> moduleIterationLimits;
  std::size_t defaultCapacity = 16;  ///< messages buffered per connection
  /// Per module id of the whole application (every host), the prefix of its object ids
  /// (msg::idPrefixes); empty: derived from the application the daemon serves.
  std::map<std::string, uint32_t, std::less<>> idPrefixes;
  /// Warn when a connection's buffer has stayed full this long (ns).
  uint64_t fullWarningNs = 2'000'000'000;
  /// Gives every module a trace ring (ipc::TraceRing) for `--trace`.
  bool trace = false;
  /// Links to the other hosts' daemons (vrflow-daemon under `vrflow launch`); null when every
  /// connection stays on this daemon.
  net::Transport* transport = nullptr;
  /// The connections that cross this host's boundary, served through `transport`.
  std::vector<net::RemoteConnection> remote;
  /// Index in the whole application of each of `application.connections` (this host's share);
  /// empty when the application given is the whole one.
  std::vector<uint32_t> connectionChannels;
  /// Opt-in busy wait (ns) of the daemon and its modules before they sleep for a message, at
  /// most kMaxSpinNs; -1: from $VRFLOW_SPIN_US (microseconds), 0 when unset.
  int64_t spinNs = -1;
};

/// The prefix of each module's object ids in `application` (msg::idPrefixes of its module ids).
std::map<std::string, uint32_t, std::less<>> idPrefixesOf(const app::Application& application);

/// The longest opt-in spin: 1 ms.
inline constexpr int64_t kMaxSpinNs = 1'000'000;

/// The spin a daemon uses when DaemonOptions::spinNs is -1: $VRFLOW_SPIN_US in ns, 0 when the
/// variable is unset or empty; an error naming the variable when it is not a whole number of
/// microseconds from 0 to 1000.
Result<int64_t> spinFromEnvironment();

/// A module the daemon serves: what to start and where its shared state lives.
struct ModuleProcess {
  std::string id;
  std::string host;
  std::string executable;
  /// Arguments after the executable: a script module's script (its executable is the
  /// interpreter).
  std::vector<std::string> arguments;
  /// Environment entries set for the module over the inherited ones (a script module's
  /// PYTHONPATH to this build's `vrflow` package).
  std::vector<std::string> environment;
  int slotIndex = 0;
  /// Above 1: started as this many MPI ranks through mpirun (app::ModuleType::mpiRanksParam).
  int mpiRanks = 1;
};

/// Counters of one connection, for the run report.
struct ConnectionStats {
  std::string from, to;
  uint64_t messages = 0;
  uint64_t bytes = 0;
  uint64_t dropped = 0;
  bool stayedFull = false;
};

/// The last message an output port sent, for the run report.
struct OutputStats {
  std::string module, port;
  uint64_t messages = 0;
  bool hasLast = false;
  uint64_t lastDigest = 0;
  uint64_t lastIteration = 0;
};

/// One port of a filter (or of a module port's default filter) and what went through it.
struct FilterPortStats {
  std::string port;       ///< the port's name; a variadic input: the connection's source
  uint64_t messages = 0;  ///< input: messages that reached the filter; output: messages emitted
  /// Input: messages the filter consumed without passing them on, by reason; output: messages
  /// emitted with nothing connected ("not connected").
  std::map<std::string, uint64_t, std::less<>> dropped;
};

/// Per-port counters of one filter, for the run report and the live statistics.
struct FilterStats {
  std::string id, type;
  std::vector<FilterPortStats> inputs, outputs;
};

/// A connection's live counters, published by the routing thread about twice a second.
struct QueueSnapshot {
  std::string from, to;
  std::size_t length = 0, capacity = 0;
  uint64_t messages = 0, bytes = 0, dropped = 0;
};

/// A host's daemon: owns the shared-memory segment, the control table of its modules, and the
/// filter network between them, which it runs on its own thread. Routing goes through Sink
/// objects, so destinations on other hosts slot in as another kind of sink.
class Daemon {
 public:
  /// Builds the network of `application` (already validated against `catalog`).
  static Result<std::unique_ptr<Daemon>> create(const app::Application& application,
                                                const app::Catalog& catalog,
                                                const DaemonOptions& options);
  ~Daemon();
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  ipc::Segment& segment();
  const std::vector<ModuleProcess>& modules() const;
  /// The host side of module slot `index` (ModuleProcess::slotIndex).
  ipc::ModuleSlotDaemon slot(int index) const;

  /// Starts the routing thread (filters' start() run first).
  Status start();
  /// Tells the daemon a module process has ended (its outputs close once drained).
  void moduleEnded(int index);
  /// Asks every module to stop and wakes them all.
  void requestStop();
  /// Stops the routing thread and drops every buffered message.
  void shutdown();

  /// The first protocol violation by a module (bad handle, malformed message), or empty.
  std::string fatalError();
  /// Warnings raised while running (full queues, filter problems); thread-safe snapshot.
  std::vector<std::string> takeWarnings();
  /// When the run is traced: the parts of the messages concatenated since the last call.
  std::vector<ipc::TraceMerge> takeTraceMerges();
  /// Live queue lengths and counters (thread-safe; at most about 0.5 s old).
  std::vector<QueueSnapshot> queueSnapshot();
  /// Live per-port counters of every filter (thread-safe; at most about 0.5 s old).
  std::vector<FilterStats> filterSnapshot();
  /// Statistics; call after shutdown().
  std::vector<ConnectionStats> connectionStats() const;
  std::vector<OutputStats> outputStats() const;
  std::vector<FilterStats> filterStats() const;
  /// True when a filter or connection upstream of module `index` (through filters and other
  /// modules) dropped messages: a reason for it to receive fewer than its producers sent.
  bool droppedUpstreamOf(int index) const;

 private:
  struct Impl;
  Daemon();
  std::unique_ptr<Impl> impl_;
};

}  // namespace vrflow::daemon
