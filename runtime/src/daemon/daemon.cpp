#include "vrflow/daemon/daemon.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "builtin_filters.hpp"
#include "graph.hpp"
#include "vrflow/message/digest.hpp"

namespace vrflow::daemon {
namespace {

constexpr uint32_t kOutputRingCapacity = 16;
constexpr uint32_t kInputRingCapacity = 16;
constexpr int64_t kIdleSleepNs = 100'000'000;

uint64_t nowNs() {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::steady_clock::now().time_since_epoch())
                                   .count());
}

void copyName(char (&dst)[ipc::kNameBytes], const std::string& src) {
  std::strncpy(dst, src.c_str(), ipc::kNameBytes - 1);
  dst[ipc::kNameBytes - 1] = '\0';
}

std::map<std::string, std::string> toMap(const std::vector<app::Param>& params) {
  std::map<std::string, std::string> map;
  for (const auto& p : params) map[p.name] = p.value;
  return map;
}

}  // namespace

struct Daemon::Impl {
  DaemonOptions options;
  ipc::Segment segment;
  std::unique_ptr<Graph> graph;
  std::vector<ModuleProcess> modules;
  ipc::ModuleSlot* slots = nullptr;
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
  Result<Node*> addNode(const std::string& id, const std::string& type,
                        std::map<std::string, std::string> params, std::vector<std::string> inputs,
                        std::vector<std::string> outputs);
  void loop();
  bool pass();
  void checkFullQueues(uint64_t now);
  void publishWarnings();
};

Daemon::Daemon() : impl_(std::make_unique<Impl>()) {}

Daemon::~Daemon() {
  shutdown();
}

Result<std::unique_ptr<Daemon>> Daemon::create(const app::Application& application,
                                               const app::Catalog& catalog,
                                               const DaemonOptions& options) {
  std::unique_ptr<Daemon> daemon(new Daemon());
  Impl& d = *daemon->impl_;
  d.options = options;
  auto segment = ipc::Segment::create(options.segmentBytes, options.hostId);
  if (!segment) return segment.error();
  d.segment = std::move(*segment);
  d.graph = std::make_unique<Graph>(d.segment);
  d.graph->traceMerges = options.trace;
  if (options.transport != nullptr) {
    options.transport->attachSegment(d.segment);
    auto* bell = &d.segment.header().daemonBell;
    options.transport->setArrivalCallback([bell] { bell->ring(); });
  }
  if (auto status = d.build(application, catalog); !status) return status.error();
  return daemon;
}

Result<Node*> Daemon::Impl::addNode(const std::string& id, const std::string& type,
                                    std::map<std::string, std::string> params,
                                    std::vector<std::string> inputs,
                                    std::vector<std::string> outputs) {
  const FilterSpec* spec = FilterRegistry::instance().find(type);
  if (spec == nullptr) return makeError("unknown filter type '" + type + "' for '" + id + "'");
  auto node = std::make_unique<Node>(*graph, id, type, std::move(params));
  node->inputNames = std::move(inputs);
  node->outputNames = std::move(outputs);
  // Named inputs get their queues when connected; a factory already sees how many there are.
  node->inputs.assign(node->inputNames.size(), nullptr);
  node->outputs.resize(node->outputNames.size());
  auto filter = spec->factory(*node);
  if (!filter) return filter.error();
  node->filter = std::move(*filter);
  graph->nodes.push_back(std::move(node));
  return graph->nodes.back().get();
}

Status Daemon::Impl::build(const app::Application& application, const app::Catalog& catalog) {
  // The control table and one slot per module.
  const uint64_t tableOffset = segment.reserve(sizeof(ipc::ControlTable));
  const uint64_t slotsOffset =
      segment.reserve(sizeof(ipc::ModuleSlot) * application.modules.size());
  if (tableOffset == 0 || (slotsOffset == 0 && !application.modules.empty())) {
    return makeError("shared-memory segment too small for the control table");
  }
  auto* table = new (segment.at<void>(tableOffset)) ipc::ControlTable();
  table->moduleCount = static_cast<uint32_t>(application.modules.size());
  segment.header().idCounter.store(
      (std::min<uint32_t>(table->moduleCount, ipc::kIdBlockModules) + 1) << ipc::kIdBlockBits);
  table->modulesOffset = slotsOffset;
  slots = segment.at<ipc::ModuleSlot>(slotsOffset);
  ended = std::vector<std::atomic<bool>>(application.modules.size());
  moduleOutputs.resize(application.modules.size());
  hasDataInputs.resize(application.modules.size());
  graph->countsIterations = options.iterationLimit != 0 || !options.moduleIterationLimits.empty();

  // Which ports are connected.
  std::map<std::pair<std::string, std::string>, int> fanIn;
  std::map<std::pair<std::string, std::string>, int> fanOut;
  for (const auto& c : application.connections) {
    ++fanOut[{c.from.node, c.from.port}];
    ++fanIn[{c.to.node, c.to.port}];
  }
  for (const auto& r : options.remote) {
    if (r.outgoing) {
      ++fanOut[{r.connection.from.node, r.connection.from.port}];
    } else {
      ++fanIn[{r.connection.to.node, r.connection.to.port}];
    }
  }

  for (std::size_t m = 0; m < application.modules.size(); ++m) {
    const app::Module& module = application.modules[m];
    const app::ModuleType* type = catalog.findModule(module.package, module.type);
    if (type == nullptr) {
      return makeError("unknown module type '" + module.package + "/" + module.type + "'");
    }
    auto* slot = new (&slots[m]) ipc::ModuleSlot();
    rings.emplace_back();
    outputNames.emplace_back();
    for (auto& bucket : slot->histogram) bucket.store(0);
    copyName(slot->id, module.id);
    const std::string host = app::effectiveHost(application, module.host);
    copyName(slot->host, host);
    slot->iterationLimit = options.iterationLimit;
    if (const auto limit = options.moduleIterationLimits.find(module.id);
        limit != options.moduleIterationLimits.end()) {
      slot->iterationLimit = limit->second;
    }
    if (options.trace) {
      slot->traceOffset = segment.reserve(sizeof(ipc::TraceRing));
      if (slot->traceOffset == 0) return makeError("shared-memory segment too small for tracing");
      new (segment.at<void>(slot->traceOffset)) ipc::TraceRing();
    }
    slot->endItAfterWait = module.endIt == app::EndItTiming::AfterWait ? 1 : 0;
    modules.push_back({module.id, host, type->executable, static_cast<int>(m)});

    // Parameters: manifest defaults, overridden by the file.
    std::map<std::string, std::string> values;
    for (const auto& spec : type->params) values[spec.name] = spec.defaultValue;
    for (const auto& p : module.params) values[p.name] = p.value;
    // A relative path in a file parameter names a file beside the application when one exists
    // there (input data shipped with it); otherwise it stays relative to the working directory
    // (outputs). The same rule as a manifest's executable.
    if (!application.file.empty()) {
      const auto base = std::filesystem::path(application.file).parent_path();
      for (const auto& spec : type->params) {
        auto found = values.find(spec.name);
        if (spec.type != app::ParamType::File || found == values.end() || found->second.empty())
          continue;
        const std::filesystem::path path(found->second);
        std::error_code error;
        if (path.is_relative() && std::filesystem::is_regular_file(base / path, error)) {
          found->second = (base / path).lexically_normal().string();
        }
      }
    }
    if (!type->mpiRanksParam.empty()) {  // validated as an int parameter in range
      modules.back().mpiRanks = std::max(1, std::atoi(values[type->mpiRanksParam].c_str()));
    }
    std::string text;
    for (const auto& [name, value] : values) text += name + "=" + value + "\n";
    slot->paramsOffset = segment.reserve(text.size() + 1, 8);
    if (slot->paramsOffset == 0) return makeError("shared-memory segment too small");
    std::memcpy(segment.at<char>(slot->paramsOffset), text.c_str(), text.size() + 1);
    slot->paramsBytes = static_cast<uint32_t>(text.size());

    const auto ports = catalog.portsOf(module);
    if (ports.size() > ipc::kMaxPortsPerModule) {
      return makeError("module '" + module.id + "' has more than " +
                       std::to_string(ipc::kMaxPortsPerModule) + " ports");
    }
    slot->portCount = static_cast<uint32_t>(ports.size());
    for (std::size_t p = 0; p < ports.size(); ++p) {
      const app::PortSpec& spec = ports[p];
      ipc::PortSlot& port = slot->ports[p];
      copyName(port.name, spec.name);
      outputNames[m].push_back(spec.name);
      port.isInput = spec.isInput ? 1 : 0;
      port.stampsOnly = spec.stampsOnly ? 1 : 0;
      const auto key = std::make_pair(module.id, spec.name);
      const int fan = spec.isInput ? fanIn[key] : fanOut[key];
      const app::InputConfig* config =
          spec.isInput ? app::findInputConfig(module, spec.name) : nullptr;
      const int initial = config != nullptr ? config->initialMessages : 0;
      if (initial < 0 || initial > kMaxInitialMessages) {
        return makeError("module '" + module.id + "' input '" + spec.name +
                         "': initial-messages must be 0 to " + std::to_string(kMaxInitialMessages));
      }
      // An input with only initial messages and no connection is still served: it gets them.
      port.connected = (fan > 0 || initial > 0) ? 1 : 0;
      uint32_t capacity = spec.isInput ? kInputRingCapacity : kOutputRingCapacity;
      capacity = std::bit_ceil(std::max<uint32_t>(capacity, static_cast<uint32_t>(initial) + 1));
      port.ringOffset = segment.reserve(ipc::Ring::bytesFor(capacity));
      if (port.ringOffset == 0) return makeError("shared-memory segment too small for rings");
      auto* ring = new (segment.at<void>(port.ringOffset)) ipc::Ring();
      ring->init(capacity);
      rings[m].emplace_back(ring);
      if (!port.connected) continue;

      const std::string nodeId = module.id + "." + spec.name;
      if (spec.isInput) {
        std::map<std::string, std::string> params{{"initial", std::to_string(initial)}};
        const bool latest = config != nullptr && config->mode == app::InputMode::Latest;
        params["mode"] = latest ? "latest" : "fifo";
        auto node = addNode(nodeId, "port-input", std::move(params), {}, {"out"});
        if (!node) return node.error();
        (*node)->outputs[0].push_back(
            std::make_unique<RingSink>(rings[m][p], *slot, static_cast<int>(p), latest, ended[m]));
        if (!spec.stampsOnly) hasDataInputs[m] = true;
        portNodes[{static_cast<int>(m), spec.name}] = *node;
      } else {
        auto node = addNode(nodeId, "port-output", {}, {"in"}, {"out"});
        if (!node) return node.error();
        Queue& queue = graph->newQueue();
        queue.capacity = 4;
        queue.from = nodeId;
        queue.to = nodeId;
        (*node)->inputs[0] = &queue;
        graph->sources.push_back(
            {static_cast<int>(m), static_cast<int>(p), rings[m][p], &queue, false});
        portNodes[{static_cast<int>(m), spec.name}] = *node;
        if (!spec.stampsOnly) moduleOutputs[m].push_back(*node);
        outputFilters.emplace_back(nodeId, static_cast<PortOutputFilter*>((*node)->filter.get()));
      }
    }
  }

  for (const app::Filter& filter : application.filters) {
    std::vector<std::string> inputs, outputs;
    for (const auto& spec : catalog.portsOf(filter)) {
      (spec.isInput ? inputs : outputs).push_back(spec.name);
    }
    // Parameters: the catalog's defaults, overridden by the file.
    std::map<std::string, std::string> params;
    if (const app::FilterType* type = catalog.findFilter(filter.type)) {
      for (const auto& spec : type->params) params[spec.name] = spec.defaultValue;
    }
    for (auto& [name, value] : toMap(filter.params)) params[name] = value;
    auto node = addNode(filter.id, filter.type, std::move(params), inputs, outputs);
    if (!node) return node.error();
    filterNodes[filter.id] = *node;
  }

  // Connections, in file order: each is a queue in front of its destination.
  auto moduleIndex = [&](const std::string& id) {
    for (std::size_t m = 0; m < application.modules.size(); ++m) {
      if (application.modules[m].id == id) return static_cast<int>(m);
    }
    return -1;
  };
  // A module input fed by several connections concatenates them in file order, whichever
  // host each comes from: attach them sorted by their index in the whole application.
  struct VariadicInput {
    uint32_t key;
    Node* to;
    Queue* queue;
  };
  std::vector<VariadicInput> variadicInputs;
  // The node and output index a connection leaves from (nullptr: no such port).
  auto findSource = [&](const app::Endpoint& e) -> std::pair<Node*, std::size_t> {
    if (const int m = moduleIndex(e.node); m >= 0) return {portNodes[{m, e.port}], 0};
    if (filterNodes.count(e.node) == 0) return {nullptr, 0};
    Node* node = filterNodes[e.node];
    const auto& names = node->outputNames;
    const auto index =
        static_cast<std::size_t>(std::find(names.begin(), names.end(), e.port) - names.begin());
    return {index == names.size() ? nullptr : node, index};
  };
  // The node and input index a connection arrives at: -1 for a module port or a filter's
  // variadic input (nullptr: no such port).
  auto findTarget = [&](const app::Endpoint& e) -> std::pair<Node*, int> {
    if (const int m = moduleIndex(e.node); m >= 0) return {portNodes[{m, e.port}], -1};
    if (filterNodes.count(e.node) == 0) return {nullptr, -1};
    Node* node = filterNodes[e.node];
    const auto& names = node->inputNames;
    const auto index =
        static_cast<int>(std::find(names.begin(), names.end(), e.port) - names.begin());
    return {index == static_cast<int>(names.size()) ? nullptr : node, index};
  };
  // The connection's queue in front of `to`; `key` orders it among a variadic input's queues.
  auto attachQueue = [&](const app::Connection& c, Node* to, int toInput,
                         uint32_t key) -> Result<Queue*> {
    Queue& queue = graph->newQueue();
    queue.capacity =
        c.capacity > 0 ? static_cast<std::size_t>(c.capacity) : options.defaultCapacity;
    queue.policy = c.policy;
    queue.from = app::toString(c.from);
    queue.to = app::toString(c.to);
    queue.isConnection = true;
    if (toInput < 0) {
      variadicInputs.push_back({key, to, &queue});
    } else {
      if (to->inputs[static_cast<std::size_t>(toInput)] != nullptr) {
        return makeError("filter input " + app::toString(c.to) + " has more than one connection");
      }
      to->inputs[static_cast<std::size_t>(toInput)] = &queue;
    }
    return &queue;
  };
  for (std::size_t connectionIndex = 0; connectionIndex < application.connections.size();
       ++connectionIndex) {
    const app::Connection& c = application.connections[connectionIndex];
    const auto [from, fromOutput] = findSource(c.from);
    const auto [to, toInput] = findTarget(c.to);
    if (from == nullptr || to == nullptr) {
      return makeError("connection " + app::toString(c.from) + " -> " + app::toString(c.to) +
                       " names a missing port");
    }
    const uint32_t key = connectionIndex < options.connectionChannels.size()
                             ? options.connectionChannels[connectionIndex]
                             : static_cast<uint32_t>(connectionIndex);
    auto queue = attachQueue(c, to, toInput, key);
    if (!queue) return queue.error();
    from->outputs[fromOutput].push_back(std::make_unique<QueueSink>(**queue));
  }
  // Connections from or to another host: a sink that sends, or a queue fed by the transport.
  for (const net::RemoteConnection& r : options.remote) {
    const app::Connection& c = r.connection;
    if (options.transport == nullptr)
      return makeError("connection crosses hosts without a transport");
    if (r.outgoing) {
      const auto [from, fromOutput] = findSource(c.from);
      if (from == nullptr)
        return makeError("connection " + app::toString(c.from) + " names a missing port");
      from->outputs[fromOutput].push_back(options.transport->makeSink(r.channel));
      continue;
    }
    const auto [to, toInput] = findTarget(c.to);
    if (to == nullptr)
      return makeError("connection " + app::toString(c.to) + " names a missing port");
    auto queue = attachQueue(c, to, toInput, r.channel);
    if (!queue) return queue.error();
    remoteInputs.push_back({r.channel, *queue, std::make_unique<QueueSink>(**queue)});
  }
  std::stable_sort(variadicInputs.begin(), variadicInputs.end(),
                   [](const VariadicInput& a, const VariadicInput& b) { return a.key < b.key; });
  for (const auto& v : variadicInputs) v.to->inputs.push_back(v.queue);
  // A filter input left unconnected never receives anything.
  for (auto& node : graph->nodes) {
    for (auto& input : node->inputs) {
      if (input == nullptr) {
        Queue& queue = graph->newQueue();
        queue.closed = true;
        input = &queue;
      }
      queueOwners[input] = node.get();
    }
  }
  segment.header().controlOffset = tableOffset;
  built = true;
  return {};
}

ipc::Segment& Daemon::segment() {
  return impl_->segment;
}
const std::vector<ModuleProcess>& Daemon::modules() const {
  return impl_->modules;
}
ipc::ModuleSlot& Daemon::slot(int index) {
  return impl_->slots[index];
}

Status Daemon::start() {
  Impl& d = *impl_;
  for (auto& node : d.graph->nodes) {
    if (auto status = node->filter->start(*node); !status) return status;
  }
  d.running.store(true);
  d.thread = std::thread([&d] { d.loop(); });
  return {};
}

void Daemon::moduleEnded(int index) {
  impl_->ended[static_cast<std::size_t>(index)].store(true, std::memory_order_release);
  impl_->segment.header().daemonBell.ring();
}

void Daemon::requestStop() {
  Impl& d = *impl_;
  d.segment.header().stopRequested.store(1, std::memory_order_release);
  for (const auto& module : d.modules) d.slots[module.slotIndex].bell.ring();
  d.segment.header().daemonBell.ring();
}

void Daemon::shutdown() {
  Impl& d = *impl_;
  if (d.running.exchange(false)) {
    d.segment.header().daemonBell.ring();
    d.thread.join();
  }
  if (!d.graph || !d.built) return;
  // Route what the modules sent last (their processes have ended by now), so that the report
  // sees every message that was put.
  while (d.pass()) {
  }
  d.publishWarnings();
  // Drop every message still buffered: in queues, and in the rings of every module.
  for (auto& queue : d.graph->queues) queue.items.clear();
  for (const auto& moduleRings : d.rings) {
    for (const auto& ring : moduleRings) {
      uint64_t handle = 0;
      while (ring.pop(handle)) {
        if (d.segment.validHandle(handle)) d.segment.release(handle);
      }
    }
  }
}

void Daemon::Impl::loop() {
  auto& bell = segment.header().daemonBell;
  uint64_t lastFullCheck = 0;
  uint64_t lastSnapshot = 0;
  while (running.load(std::memory_order_acquire)) {
    const uint32_t seen = bell.prepare();
    bool progressed = false;
    while (pass()) progressed = true;
    const uint64_t now = nowNs();
    if (now - lastFullCheck > 100'000'000) {
      checkFullQueues(now);
      markUnneededModules();
      lastFullCheck = now;
    }
    if (now - lastSnapshot > 500'000'000) {
      publishSnapshot();
      lastSnapshot = now;
    }
    publishWarnings();
    if (progressed) continue;
    // Sleep until a message moves, or until the earliest timer a filter asked for.
    int64_t sleepNs = kIdleSleepNs;
    if (graph->wakeAtNs != 0) {
      const uint64_t current = nowNs();
      sleepNs = graph->wakeAtNs <= current
                    ? 0
                    : std::min<int64_t>(sleepNs, static_cast<int64_t>(graph->wakeAtNs - current));
    }
    if (sleepNs > 0) bell.sleep(seen, sleepNs);
  }
}

// One sweep over sources and filters; true if anything moved.
bool Daemon::Impl::pass() {
  const uint64_t before = graph->operations;
  graph->wakeAtNs = 0;  // filters that still need a timer ask again in process()
  std::size_t buffered = 0;
  for (auto& source : graph->sources) {
    if (source.closed) continue;
    ipc::ModuleSlot& slot = slots[source.module];
    const ipc::RingRef& ring = source.ring;
    bool popped = false;
    uint64_t handle = 0;
    while (source.queue->items.size() < source.queue->capacity && ring.pop(handle)) {
      // A cheap check at the door, so that a bad message is blamed on the module that sent it
      // (receivers check every byte when they read it).
      const char* problem = nullptr;
      if (!segment.validHandle(handle)) {
        problem = "an invalid handle";
      } else if (segment.block(handle).refs.load(std::memory_order_relaxed) == 0) {
        problem = "a message it no longer holds";
      } else {
        const auto total = msg::MessageView::peekTotalSize(segment.bytes(handle));
        if (!total || *total != segment.block(handle).used) problem = "a malformed message";
      }
      if (problem != nullptr) {
        // A module that breaks the protocol has a bug: the run stops, naming it.
        std::lock_guard lock(warningsMutex);
        if (fatal.empty()) {
          fatal = "module '" + modules[static_cast<std::size_t>(source.module)].id + "' sent " +
                  problem + " on output '" +
                  outputNames[static_cast<std::size_t>(source.module)]
                             [static_cast<std::size_t>(source.port)] +
                  "'";
        }
        if (segment.validHandle(handle) && segment.block(handle).refs.load() != 0) {
          segment.release(handle);
        }
        continue;
      }
      source.queue->items.emplace_back(&segment, handle);
      ++source.queue->messages;
      popped = true;
      ++graph->operations;
    }
    if (popped) slot.bell.ring();  // room on the module's output ring
    const bool moduleDone =
        ended[static_cast<std::size_t>(source.module)].load(std::memory_order_acquire) ||
        slot.state.load(std::memory_order_acquire) ==
            static_cast<uint32_t>(ipc::ModuleState::Finished);
    if (moduleDone && ring.empty()) {
      source.closed = true;
      source.queue->closed = true;
      ++graph->operations;
    }
  }
  for (auto& input : remoteInputs) {
    if (input.queue->closed) continue;
    bool closed = false;
    if (options.transport->receive(input.channel, *input.sink, closed) > 0) ++graph->operations;
    if (closed) {
      input.queue->closed = true;
      ++graph->operations;
    }
  }
  for (auto& node : graph->nodes) {
    if (node->closed) {
      // Nothing will ever consume these: drop them so that producers are not held back.
      for (std::size_t input = 0; input < node->inputs.size(); ++input) {
        Queue* queue = node->inputs[input];
        if (!queue->items.empty()) {
          queue->dropped += queue->items.size();
          node->countDropped(input, queue->items.size(), "filter ended");
          queue->items.clear();
          ++graph->operations;
        }
      }
      continue;
    }
    node->filter->process(*node);
    if (node->filter->exhausted(*node)) {
      node->closed = true;
      for (auto& output : node->outputs) {
        for (auto& sink : output) sink->close();
      }
      ++graph->operations;
    }
    for (auto* queue : node->inputs) buffered += queue->items.size();
  }
  const bool moved = graph->operations != before || buffered != lastBuffered;
  lastBuffered = buffered;
  return moved;
}

void Daemon::Impl::checkFullQueues(uint64_t now) {
  for (auto& queue : graph->queues) {
    if (!queue.isConnection) continue;
    if (queue.items.size() < queue.capacity) {
      queue.fullSinceNs = 0;
      continue;
    }
    if (queue.fullSinceNs == 0) queue.fullSinceNs = now;
    if (!queue.warnedFull && now - queue.fullSinceNs > options.fullWarningNs) {
      queue.warnedFull = true;
      queue.stayedFull = true;
      const char* policy = queue.policy == app::QueuePolicy::Block        ? "block"
                           : queue.policy == app::QueuePolicy::DropOldest ? "drop-oldest"
                                                                          : "drop-newest";
      // What it means, in the words of the two ends (the ids before the port names).
      const auto owner = [](const std::string& port) {
        return "'" + port.substr(0, port.rfind('.')) + "'";
      };
      const std::string from = owner(queue.from), to = owner(queue.to);
      const std::string effect = queue.policy == app::QueuePolicy::Block
                                     ? ", so " + to + " paces " + from
                                     : "; what does not fit is dropped";
      graph->warnings.push_back("connection " + queue.from + " -> " + queue.to + " stayed full (" +
                                std::to_string(queue.capacity) + " messages, policy " + policy +
                                "): " + to + " takes messages slower than " + from + " sends them" +
                                effect);
    }
  }
}

void Daemon::Impl::publishSnapshot() {
  std::vector<QueueSnapshot> next;
  for (const auto& queue : graph->queues) {
    if (!queue.isConnection) continue;
    next.push_back({queue.from, queue.to, queue.items.size(), queue.capacity, queue.messages,
                    queue.bytes, queue.dropped});
  }
  auto filters = collectFilterStats();
  std::lock_guard lock(warningsMutex);
  snapshot = std::move(next);
  filterSnapshot = std::move(filters);
}

std::vector<FilterStats> Daemon::Impl::collectFilterStats() const {
  std::vector<FilterStats> all;
  for (const auto& node : graph->nodes) {
    FilterStats stats{node->name(), node->type, {}, {}};
    for (std::size_t i = 0; i < node->inputs.size(); ++i) {
      FilterPortStats port;
      port.port = i < node->inputNames.size() ? node->inputNames[i] : node->inputs[i]->from;
      port.messages = node->inputs[i]->messages;
      if (i < node->dropped.size()) {
        for (const auto& [reason, count] : node->dropped[i]) port.dropped[reason] = count;
      }
      stats.inputs.push_back(std::move(port));
    }
    for (std::size_t o = 0; o < node->outputs.size(); ++o) {
      FilterPortStats port;
      port.port = o < node->outputNames.size() ? node->outputNames[o] : "out";
      port.messages = o < node->sent.size() ? node->sent[o] : 0;
      if (o < node->sentNowhere.size() && node->sentNowhere[o] != 0) {
        port.dropped["not connected"] = node->sentNowhere[o];
      }
      stats.outputs.push_back(std::move(port));
    }
    all.push_back(std::move(stats));
  }
  return all;
}

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
    if (ended[m].load(std::memory_order_acquire) ||
        slots[m].state.load(std::memory_order_acquire) ==
            static_cast<uint32_t>(ipc::ModuleState::Finished)) {
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
            one = reachOfModule(static_cast<std::size_t>(&ring->slot() - slots));
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
    ipc::ModuleSlot& slot = slots[m];
    if (moduleOutputs[m].empty() || hasDataInputs[m] ||
        slot.unneeded.load(std::memory_order_relaxed) != 0 || reachOfModule(m) != OnlyEnded ||
        ended[m].load(std::memory_order_acquire) ||
        slot.state.load(std::memory_order_acquire) ==
            static_cast<uint32_t>(ipc::ModuleState::Finished)) {
      continue;
    }
    slot.unneeded.store(1, std::memory_order_release);
    slot.bell.ring();
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

std::vector<FilterStats> Daemon::filterSnapshot() {
  std::lock_guard lock(impl_->warningsMutex);
  return impl_->filterSnapshot;
}

std::vector<FilterStats> Daemon::filterStats() const {
  return impl_->collectFilterStats();
}

std::vector<QueueSnapshot> Daemon::queueSnapshot() {
  std::lock_guard lock(impl_->warningsMutex);
  return impl_->snapshot;
}

void Daemon::Impl::publishWarnings() {
  if (graph->warnings.empty() && graph->merges.empty()) return;
  std::lock_guard lock(warningsMutex);
  for (auto& w : graph->warnings) warnings.push_back(std::move(w));
  graph->warnings.clear();
  traceMerges.insert(traceMerges.end(), graph->merges.begin(), graph->merges.end());
  graph->merges.clear();
}

std::string Daemon::fatalError() {
  std::lock_guard lock(impl_->warningsMutex);
  return impl_->fatal;
}

std::vector<std::string> Daemon::takeWarnings() {
  std::lock_guard lock(impl_->warningsMutex);
  return std::exchange(impl_->warnings, {});
}

std::vector<ipc::TraceMerge> Daemon::takeTraceMerges() {
  std::lock_guard lock(impl_->warningsMutex);
  return std::exchange(impl_->traceMerges, {});
}

std::vector<ConnectionStats> Daemon::connectionStats() const {
  std::vector<ConnectionStats> stats;
  for (const auto& queue : impl_->graph->queues) {
    if (!queue.isConnection) continue;
    stats.push_back(
        {queue.from, queue.to, queue.messages, queue.bytes, queue.dropped, queue.stayedFull});
  }
  return stats;
}

std::vector<OutputStats> Daemon::outputStats() const {
  std::vector<OutputStats> stats;
  for (const auto& [name, filter] : impl_->outputFilters) {
    OutputStats s;
    const auto dot = name.rfind('.');
    s.module = name.substr(0, dot);
    s.port = name.substr(dot + 1);
    s.messages = filter->forwarded();
    if (filter->last().valid()) {
      if (auto view = filter->last().view()) {
        s.hasLast = true;
        s.lastDigest = msg::digest(*view);
        s.lastIteration = view->stamps().iteration;
      }
    }
    stats.push_back(std::move(s));
  }
  return stats;
}

}  // namespace vrflow::daemon
