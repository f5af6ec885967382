#pragma once

// Internal to the daemon: the state behind Daemon, shared by the files that implement it
// (daemon.cpp: lifetime and the routing loop; daemon_build.cpp: the network from the
// application; daemon_stats.cpp: statistics and snapshots; daemon_reach.cpp: what modules'
// outputs reach).

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "builtin_filters.hpp"
#include "graph.hpp"
#include "vrflow/daemon/daemon.hpp"
#include "vrflow/ipc/module_slot_daemon.hpp"

namespace vrflow::daemon {

struct Daemon::Impl {
  DaemonOptions options;
  ipc::Segment segment;
  std::unique_ptr<Graph> graph;
  std::vector<ModuleProcess> modules;
  ipc::ControlTableDaemon table;
  std::vector<ipc::ModuleSlotDaemon> slots;  ///< per module
  std::vector<std::atomic<bool>> ended;
  std::vector<std::vector<ipc::RingRef>>
      rings;  ///< per module and port, kept out of modules' reach
  std::vector<std::vector<std::string>> outputNames;  ///< per module and port, for messages
  // Per module and port index: the node fed by that port (output filter) or feeding it.
  std::map<std::pair<int, std::string>, Node*> portNodes;
  std::map<std::string, Node*> filterNodes;
  std::vector<std::vector<Node*>> moduleOutputs;  ///< per module: its connected data outputs' nodes
  std::vector<bool> hasDataInputs;                ///< per module: a connected data input
  std::map<const Queue*, Node*> queueOwners;      ///< the node each filter input queue feeds
  struct RemoteInput {
    uint32_t channel;
    Queue* queue;
    std::unique_ptr<QueueSink> sink;
  };
  std::vector<RemoteInput> remoteInputs;  ///< connections arriving from other hosts
  std::vector<std::pair<std::string, PortOutputFilter*>> outputFilters;  // "module.port"
  std::thread thread;
  /// The routing network (graph, queues, sources): held by the thread that routes, the routing
  /// thread or a transport's I/O thread on arrivals (routeArrivals).
  std::mutex routingMutex;
  /// The routing thread, rung while an I/O thread held routingMutex, left the pass to it: the
  /// I/O thread passes again once it lets go (no block on the mutex, no wake-up to hand back).
  std::atomic<bool> passWanted{false};
  std::atomic<bool> running{false};
  bool built = false;  ///< the network was fully built (shutdown() has something to drain)
  std::size_t lastBuffered = 0;  ///< messages buffered after the previous pass
  std::mutex warningsMutex;
  std::vector<std::string> warnings;
  std::string fatal;  ///< first protocol violation by a module (guarded by warningsMutex)
  std::vector<ipc::TraceMerge> traceMerges;  ///< guarded by warningsMutex
  std::vector<QueueSnapshot> snapshot;       ///< guarded by warningsMutex
  std::vector<FilterStats> filterSnapshot;   ///< guarded by warningsMutex
  void publishSnapshot();
  std::vector<FilterStats> collectFilterStats() const;
  void markUnneededModules();

  Status build(const app::Application& application, const app::Catalog& catalog);
  Result<Node*> addNode(const std::string& id, const std::string& type, Parameters params,
                        std::vector<std::string> inputs, std::vector<std::string> outputs);
  void loop();
  void routeArrivals();
  bool pass();
  void checkFullQueues(uint64_t now);
  void publishWarnings();
};

}  // namespace vrflow::daemon
