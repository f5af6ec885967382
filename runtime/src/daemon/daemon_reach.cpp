#include <functional>
#include <map>
#include <set>
#include <vector>

#include "daemon_impl.hpp"

// What the modules' outputs reach through the routing network: which modules nothing needs any
// more, and which modules' inputs lost messages on the way.
namespace vrflow::daemon {

// A module without data inputs (a source, a capture device) whose data outputs reach only
// modules that have ended is asked to end (wait() returns false, EndCause::Unneeded): what it
// sends would be dropped. A module with data inputs is never asked: it goes on with what is
// buffered for it and ends with its input; for the modules feeding it, it counts as ended when
// its own data outputs reach only ended modules. Signals (stamps-only ports: beginIt, endIt)
// do not count, and neither does a connection to another host, which counts as running.
void Daemon::Impl::markUnneededModules() {
  enum Reach { Nothing = 0, OnlyEnded = 1, Running = 2 };
  std::map<const Node*, Reach> nodeMemo;
  std::map<std::size_t, Reach> moduleMemo;
  std::function<Reach(const Node*)> reachOfNode;
  // What a module's data outputs reach, seen from a producer of it.
  const auto reachOfModule = [&](std::size_t m) -> Reach {
    if (ended[m].load(std::memory_order_acquire) || slots[m].finished()) {
      return OnlyEnded;
    }
    if (const auto found = moduleMemo.find(m); found != moduleMemo.end()) return found->second;
    moduleMemo[m] = Nothing;  // a cycle back to this module adds nothing
    Reach reach = Nothing;
    for (const Node* output : moduleOutputs[m]) reach = std::max(reach, reachOfNode(output));
    // A module that sends no data anywhere (a viewer, a recorder) does useful work.
    if (reach == Nothing) reach = Running;
    moduleMemo[m] = reach;
    return reach;
  };
  reachOfNode = [&](const Node* node) -> Reach {
    if (const auto found = nodeMemo.find(node); found != nodeMemo.end()) return found->second;
    nodeMemo[node] = Nothing;  // a cycle back to this node adds nothing
    Reach reach = Nothing;
    if (!node->closed) {
      for (const auto& sinks : node->outputs) {
        for (const auto& sink : sinks) {
          Reach one = Running;
          if (const auto* ring = dynamic_cast<const RingSink*>(sink.get())) {
            one = reachOfModule(static_cast<std::size_t>(ring->module()));
          } else if (const auto* queue = dynamic_cast<const QueueSink*>(sink.get())) {
            const auto owner = queueOwners.find(&queue->queue());
            one = owner == queueOwners.end() ? Running : reachOfNode(owner->second);
          }
          reach = std::max(reach, one);
        }
      }
    }
    nodeMemo[node] = reach;
    return reach;
  };
  for (std::size_t m = 0; m < moduleOutputs.size(); ++m) {
    const ipc::ModuleSlotDaemon& slot = slots[m];
    if (moduleOutputs[m].empty() || hasDataInputs[m] || slot.unneeded() ||
        reachOfModule(m) != OnlyEnded || ended[m].load(std::memory_order_acquire) ||
        slot.finished()) {
      continue;
    }
    slot.markUnneeded();
  }
}

bool Daemon::droppedUpstreamOf(int index) const {
  const Impl& d = *impl_;
  std::map<const Queue*, const Node*> producers;  // the node that pushes into each queue
  for (const auto& node : d.graph->nodes) {
    for (const auto& sinks : node->outputs) {
      for (const auto& sink : sinks) {
        if (const auto* queue = dynamic_cast<const QueueSink*>(sink.get())) {
          producers[&queue->queue()] = node.get();
        }
      }
    }
  }
  std::set<const Node*> seen;
  std::vector<const Node*> pending;
  const auto addInputsOf = [&](int module) {
    for (const auto& [key, node] : d.portNodes) {
      if (key.first == module && node->type == "port-input") pending.push_back(node);
    }
  };
  addInputsOf(index);
  while (!pending.empty()) {
    const Node* node = pending.back();
    pending.pop_back();
    if (!seen.insert(node).second) continue;
    for (const auto& byReason : node->dropped) {
      for (const auto& entry : byReason) {
        if (entry.second != 0) return true;
      }
    }
    for (const Queue* queue : node->inputs) {
      if (queue->dropped != 0) return true;
      if (const auto found = producers.find(queue); found != producers.end()) {
        pending.push_back(found->second);
      }
      for (const auto& source : d.graph->sources) {
        if (source.queue == queue) addInputsOf(source.module);
      }
    }
  }
  return false;
}

}  // namespace vrflow::daemon
