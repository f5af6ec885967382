#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/daemon/filter.hpp"
#include "vrflow/ipc/control.hpp"
#include "vrflow/ipc/module_slot_daemon.hpp"
#include "vrflow/ipc/ring.hpp"
#include "vrflow/ipc/sink.hpp"

namespace vrflow::daemon {

/// A bounded FIFO in front of a filter input: one per connection.
struct Queue {
  std::deque<MessageRef> items;
  std::size_t capacity = 16;
  app::QueuePolicy policy = app::QueuePolicy::Block;
  bool closed = false;
  std::string from, to;
  uint64_t messages = 0, bytes = 0, dropped = 0;
  uint64_t fullSinceNs = 0;
  bool warnedFull = false;
  bool stayedFull = false;
  bool isConnection = false;  ///< false for the internal ring -> output-filter hop
};

/// Where an output's messages go: a filter's queue here, a module's input ring here, or a peer
/// daemon over the network (net::Transport::makeSink).
using Sink = ipc::Sink;

/// A sink that appends to a queue, honouring its capacity and policy.
class QueueSink final : public Sink {
 public:
  explicit QueueSink(Queue& queue) : queue_(&queue) {}
  bool hasSpace() const override {
    return queue_->policy != app::QueuePolicy::Block || queue_->items.size() < queue_->capacity;
  }
  void push(MessageRef message) override;
  void close() override { queue_->closed = true; }
  /// The queue it appends to.
  const Queue& queue() const { return *queue_; }

 private:
  Queue* queue_;
};

/// A sink that hands messages to a module's input ring and wakes the module.
class RingSink final : public Sink {
 public:
  RingSink(ipc::RingRef ring, ipc::ModuleSlotDaemon slot, int module, int port, bool onlyWhenEmpty,
           const std::atomic<bool>& moduleEnded)
      : ring_(ring),
        slot_(slot),
        module_(module),
        port_(port),
        onlyWhenEmpty_(onlyWhenEmpty),
        moduleEnded_(&moduleEnded) {}
  /// A module that has ended takes (and drops) everything, so its producers are never stuck.
  bool hasSpace() const override {
    if (ended()) return true;
    const bool space = onlyWhenEmpty_ ? ring_.empty() : !ring_.full();
    if (!space) {
      // Ask the module to ring the daemon when it takes a message; re-check, since it may
      // have taken one before it could see the request.
      slot_.requestSpace(port_);
      return onlyWhenEmpty_ ? ring_.empty() : !ring_.full();
    }
    return true;
  }
  void push(MessageRef message) override;
  void close() override { slot_.closeInput(port_); }
  bool ended() const override {
    return moduleEnded_->load(std::memory_order_acquire) || slot_.finished();
  }
  /// The index of the module it feeds.
  int module() const { return module_; }

 private:
  ipc::RingRef ring_;
  ipc::ModuleSlotDaemon slot_;
  int module_;
  int port_;
  bool onlyWhenEmpty_;
  const std::atomic<bool>* moduleEnded_;
};

class Graph;

/// A filter with its inputs (queues) and outputs (sinks); also its FilterContext.
class Node final : public FilterContext {
 public:
  Node(Graph& graph, std::string id, std::string typeName, Parameters params)
      : type(std::move(typeName)), graph_(&graph), id_(std::move(id)), params_(std::move(params)) {}

  const std::string& name() const override { return id_; }
  const Parameters& params() const override { return params_; }
  std::size_t inputCount() const override { return inputs.size(); }
  std::deque<MessageRef>& input(std::size_t i) override { return inputs[i]->items; }
  bool inputClosed(std::size_t i) const override { return inputs[i]->closed; }
  void countDropped(std::size_t i, uint64_t count, std::string_view reason) override;
  std::size_t outputCount() const override { return outputs.size(); }
  bool canEmit(std::size_t o) const override;
  void emit(std::size_t o, MessageRef message) override;
  bool outputEnded(std::size_t o) const override;
  bool runCountsIterations() const override;
  /// When the run is traced, records which parts a joined message was made of (trace arrows).
  void recordMerge(std::span<const msg::MessageView> views) override;
  Result<MessageRef> compose(std::size_t sizeHint,
                             const std::function<void(msg::MessageBuilder&)>& fill) override;
  uint64_t nowNs() const override;
  void wakeAfter(uint64_t delayNs) override;
  void warn(const std::string& message) override;

  std::unique_ptr<Filter> filter;
  std::vector<Queue*> inputs;
  std::vector<std::string> inputNames, outputNames;
  std::vector<std::vector<std::unique_ptr<Sink>>> outputs;
  bool closed = false;
  uint64_t emitted = 0;
  std::string type;  ///< the filter type ("port-input" / "port-output" for a module's ports)
  std::vector<uint64_t> sent;         ///< per output: messages emitted
  std::vector<uint64_t> sentNowhere;  ///< per output: emitted with nothing connected (dropped)
  std::vector<std::map<std::string, uint64_t, std::less<>>> dropped;  ///< per input, by reason

 private:
  Graph* graph_;
  std::string id_;
  Parameters params_;
};

/// A module output ring feeding the queue of its port's output filter.
struct ModuleSource {
  int module = 0;
  int port = 0;
  ipc::RingRef ring;
  Queue* queue = nullptr;
  bool closed = false;
};

/// The whole routing network of one daemon.
class Graph {
 public:
  explicit Graph(ipc::Segment& shared) : segment(&shared) {}
  Queue& newQueue() { return queues.emplace_back(); }

  ipc::Segment* segment;
  std::deque<Queue> queues;
  std::vector<std::unique_ptr<Node>> nodes;
  std::vector<ModuleSource> sources;
  std::vector<std::string> warnings;
  bool traceMerges = false;             ///< the run is traced: joins record `merges`
  std::vector<ipc::TraceMerge> merges;  ///< taken with the warnings (Daemon::takeTraceMerges)
  uint64_t operations = 0;              ///< bumped on every move, to detect progress
  bool countsIterations = false;        ///< every module has an iteration count (--iterations)
  uint64_t wakeAtNs = 0;                ///< earliest time a filter asked to be run again; 0 = none
};

}  // namespace vrflow::daemon
