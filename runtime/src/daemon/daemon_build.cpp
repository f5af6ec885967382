#include <algorithm>
#include <bit>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>

#include "daemon_impl.hpp"
#include "vrflow/base/executable_dir.hpp"
#include "vrflow/daemon/filter_registry.hpp"
#include "vrflow/daemon/filter_spec.hpp"
#include "vrflow/message/ids.hpp"

// Builds a daemon's routing network from the application: module slots and rings, a filter
// node per module port and per filter, a queue per connection, sinks to other hosts.
namespace vrflow::daemon {
namespace {

constexpr uint32_t kOutputRingCapacity = 16;
constexpr uint32_t kInputRingCapacity = 16;

// Who a filter node's parameters belong to, as their errors name it.
std::string filterOwner(const std::string& id, const std::string& type) {
  return "filter '" + id + "' (" + type + ")";
}

// A script module's environment: its lines reach the log as printed, and it finds the `vrflow`
// Python package of this build (build/python beside build/bin, put first on PYTHONPATH); an
// installed vrflow's package is in the interpreter's site-packages, found without help.
std::vector<std::string> scriptEnvironment() {
  std::vector<std::string> environment{"PYTHONUNBUFFERED=1"};
  const std::filesystem::path bin = executableDir();
  if (bin.empty()) return environment;
  const std::filesystem::path python = bin.parent_path() / "python";
  std::error_code error;
  if (!std::filesystem::is_regular_file(python / "vrflow" / "__init__.py", error)) {
    return environment;
  }
  std::string path = python.string();
  if (const char* inherited = std::getenv("PYTHONPATH"); inherited != nullptr && *inherited) {
    path += ":" + std::string(inherited);
  }
  environment.push_back("PYTHONPATH=" + path);
  return environment;
}

// A script module's interpreter: the manifest's, except that the default `python3`, run from a
// build tree, is the interpreter the build's `vrflow` package was built for (its path is in
// build/python/vrflow/interpreter.txt), which another python3 first on PATH may not be.
std::string scriptInterpreter(const std::string& interpreter) {
  if (interpreter != "python3") return interpreter;
  const std::filesystem::path bin = executableDir();
  if (bin.empty()) return interpreter;
  std::ifstream in(bin.parent_path() / "python" / "vrflow" / "interpreter.txt");
  std::string path;
  std::error_code error;
  if (std::getline(in, path) && std::filesystem::is_regular_file(path, error)) return path;
  return interpreter;
}

}  // namespace

std::map<std::string, uint32_t, std::less<>> idPrefixesOf(const app::Application& application) {
  std::vector<std::string> ids;
  for (const auto& module : application.modules) ids.push_back(module.id);
  const std::vector<uint32_t> prefixes = msg::idPrefixes(ids);
  std::map<std::string, uint32_t, std::less<>> byId;
  for (std::size_t m = 0; m < ids.size(); ++m) byId.emplace(ids[m], prefixes[m]);
  return byId;
}

Result<Node*> Daemon::Impl::addNode(const std::string& id, const std::string& type,
                                    Parameters params, std::vector<std::string> inputs,
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
  if (const auto& misread = node->params().firstError()) return *misread;
  node->filter = std::move(*filter);
  graph->nodes.push_back(std::move(node));
  return graph->nodes.back().get();
}

Status Daemon::Impl::build(const app::Application& application, const app::Catalog& catalog) {
  // The control table and one slot per module.
  const auto moduleCount = static_cast<uint32_t>(application.modules.size());
  auto created = ipc::ControlTableDaemon::create(segment, moduleCount);
  if (!created) return created.error();
  table = *created;
  for (uint32_t m = 0; m < moduleCount; ++m) slots.push_back(table.slot(static_cast<int>(m)));
  ended = std::vector<std::atomic<bool>>(application.modules.size());
  moduleOutputs.resize(application.modules.size());
  hasDataInputs.resize(application.modules.size());
  graph->countsIterations = options.iterationLimit != 0 || !options.moduleIterationLimits.empty();
  const auto idPrefixes =
      options.idPrefixes.empty() ? idPrefixesOf(application) : options.idPrefixes;

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
    ipc::ModuleSlotDaemon& slot = slots[m];
    rings.emplace_back();
    outputNames.emplace_back();
    const std::string host = app::effectiveHost(application, module.host);
    uint64_t iterationLimit = options.iterationLimit;
    if (const auto limit = options.moduleIterationLimits.find(module.id);
        limit != options.moduleIterationLimits.end()) {
      iterationLimit = limit->second;
    }
    const auto prefix = idPrefixes.find(module.id);
    if (prefix == idPrefixes.end()) {
      return makeError("module '" + module.id +
                       "' is not among the application's modules that ids were made for");
    }
    slot.describe(module.id, host, prefix->second, iterationLimit,
                  module.endIt == app::EndItTiming::AfterWait);
    if (options.trace) {
      if (auto status = slot.addTraceRing(); !status) return status.error();
    }
    modules.push_back({module.id, host, type->executable, {}, {}, static_cast<int>(m)});
    if (!type->script.empty()) {
      modules.back().executable = scriptInterpreter(type->executable);
      modules.back().arguments = {type->script};
      modules.back().environment = scriptEnvironment();
    }

    // Parameters: typed once, the file's values over the manifest's defaults.
    auto moduleParams =
        app::parameterSet(type->params, module.params,
                          "module '" + module.id + "' (" + type->package + "/" + type->type + ")");
    if (!moduleParams) return moduleParams.error();
    // A relative path in a file parameter that is not an output names a file beside the
    // application when one exists there (input data shipped with it); otherwise, and always for
    // an output, it stays relative to the working directory (a file left beside the application
    // never draws a run's output into the application's folder). The same rule as a manifest's
    // executable, and as validation's (package_files.cpp).
    if (!application.file.empty()) {
      const auto base = std::filesystem::path(application.file).parent_path();
      for (const auto& [name, entry] : std::map(moduleParams->entries())) {
        if (entry.type != app::ParamType::File || !entry.value) continue;
        const auto spec = std::find_if(type->params.begin(), type->params.end(),
                                       [&](const app::ParamSpec& p) { return p.name == name; });
        if (spec != type->params.end() && spec->access == app::FileAccess::Output) continue;
        const std::filesystem::path path(std::get<std::string>(*entry.value));
        std::error_code error;
        if (!path.empty() && path.is_relative() &&
            std::filesystem::is_regular_file(base / path, error)) {
          moduleParams->declare(name, entry.type, (base / path).lexically_normal().string());
        }
      }
    }
    if (!type->mpiRanksParam.empty()) {  // validated as an int parameter in range
      modules.back().mpiRanks = static_cast<int>(
          std::clamp<int64_t>(moduleParams->getInt(type->mpiRanksParam), 1, 1 << 20));
    }
    if (auto status = slot.setParams(encodeParameters(*moduleParams)); !status) {
      return status.error();
    }

    const auto ports = catalog.portsOf(module);
    if (ports.size() > ipc::kMaxPortsPerModule) {
      return makeError("module '" + module.id + "' has more than " +
                       std::to_string(ipc::kMaxPortsPerModule) + " ports");
    }
    for (std::size_t p = 0; p < ports.size(); ++p) {
      const app::PortSpec& spec = ports[p];
      outputNames[m].push_back(spec.name);
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
      const bool connected = fan > 0 || initial > 0;
      uint32_t capacity = spec.isInput ? kInputRingCapacity : kOutputRingCapacity;
      capacity = std::bit_ceil(std::max<uint32_t>(capacity, static_cast<uint32_t>(initial) + 1));
      auto ring = slot.addPort(spec.name, spec.isInput, spec.stampsOnly, connected, capacity);
      if (!ring) return ring.error();
      rings[m].push_back(*ring);
      if (!connected) continue;

      const std::string nodeId = module.id + "." + spec.name;
      if (spec.isInput) {
        Parameters params(filterOwner(nodeId, "port-input"));
        params.declare("initial", app::ParamType::Int, int64_t{initial});
        const bool latest = config != nullptr && config->mode == app::InputMode::Latest;
        params.declare("mode", app::ParamType::Enum, std::string(latest ? "latest" : "fifo"));
        auto node = addNode(nodeId, "port-input", std::move(params), {}, {"out"});
        if (!node) return node.error();
        (*node)->outputs[0].push_back(std::make_unique<RingSink>(
            rings[m][p], slot, static_cast<int>(m), static_cast<int>(p), latest, ended[m]));
        if (!spec.stampsOnly) hasDataInputs[m] = true;
        portNodes[{static_cast<int>(m), spec.name}] = *node;
      } else {
        auto node = addNode(nodeId, "port-output", Parameters(filterOwner(nodeId, "port-output")),
                            {"in"}, {"out"});
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
    // Parameters: typed once, the file's values over the filter spec's defaults.
    const app::FilterType* type = catalog.findFilter(filter.type);
    auto params = app::parameterSet(type != nullptr ? type->params : std::vector<app::ParamSpec>{},
                                    filter.params, filterOwner(filter.id, filter.type));
    if (!params) return params.error();
    auto node = addNode(filter.id, filter.type, std::move(*params), inputs, outputs);
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
  table.publish();
  built = true;
  return {};
}

}  // namespace vrflow::daemon
