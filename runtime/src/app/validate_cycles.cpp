#include <algorithm>
#include <deque>
#include <limits>

#include "validation.hpp"

namespace vrflow::app::detail {
namespace {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

struct Edge {
  std::size_t from;
  std::size_t to;
  std::size_t connection;  // index in Application::connections
};

// The graph in which a cycle deadlocks: connections between known nodes, minus those that
// start with messages already waiting (a module input with initial messages) and minus every
// connection touching a filter that emits initial messages, minus those into a filter's control
// inputs (PortSpec::gating false).
std::vector<std::vector<Edge>> blockingGraph(const Validation& v) {
  std::vector<bool> primed(v.nodes.size(), false);
  for (std::size_t i = 0; i < v.nodes.size(); ++i) {
    const NodeInfo& node = v.nodes[i];
    primed[i] =
        node.filterType != nullptr && node.filterType->initialMessagesFor(node.filter->params) > 0;
  }
  std::vector<std::vector<Edge>> out(v.nodes.size());
  for (std::size_t c = 0; c < v.app.connections.size(); ++c) {
    const Connection& connection = v.app.connections[c];
    const std::size_t from = v.indexOf(connection.from.node);
    const std::size_t to = v.indexOf(connection.to.node);
    if (from == v.nodes.size() || to == v.nodes.size() || primed[from] || primed[to]) continue;
    const auto& ports = v.nodes[to].ports;
    const auto port = std::find_if(ports.begin(), ports.end(), [&](const PortSpec& spec) {
      return spec.isInput && spec.name == connection.to.port;
    });
    if (v.nodes[to].filter != nullptr && port != ports.end() && !port->gating) continue;
    const Module* module = v.nodes[to].module;
    if (module != nullptr &&
        inputConfigOrDefault(*module, connection.to.port).initialMessages > 0) {
      continue;
    }
    out[from].push_back(Edge{from, to, c});
  }
  return out;
}

// Strongly connected components (Tarjan's algorithm, iterative so that a long chain of
// connections cannot overflow the stack). Returns the component of each node.
std::vector<std::size_t> components(const std::vector<std::vector<Edge>>& out) {
  const std::size_t n = out.size();
  std::vector<std::size_t> index(n, kNone);
  std::vector<std::size_t> low(n, 0);
  std::vector<std::size_t> component(n, kNone);
  std::vector<bool> onStack(n, false);
  std::vector<std::size_t> stack;
  std::vector<std::pair<std::size_t, std::size_t>> calls;  // node, next edge to follow
  std::size_t counter = 0;
  std::size_t componentCount = 0;
  for (std::size_t root = 0; root < n; ++root) {
    if (index[root] != kNone) continue;
    calls.emplace_back(root, 0);
    while (!calls.empty()) {
      auto& [node, next] = calls.back();
      if (next == 0 && index[node] == kNone) {
        index[node] = low[node] = counter++;
        stack.push_back(node);
        onStack[node] = true;
      }
      if (next < out[node].size()) {
        const std::size_t target = out[node][next++].to;
        if (index[target] == kNone) {
          calls.emplace_back(target, 0);
        } else if (onStack[target]) {
          low[node] = std::min(low[node], index[target]);
        }
        continue;
      }
      if (low[node] == index[node]) {
        std::size_t member = kNone;
        do {
          member = stack.back();
          stack.pop_back();
          onStack[member] = false;
          component[member] = componentCount;
        } while (member != node);
        ++componentCount;
      }
      const std::size_t finished = node;
      calls.pop_back();
      if (!calls.empty()) {
        const std::size_t parent = calls.back().first;
        low[parent] = std::min(low[parent], low[finished]);
      }
    }
  }
  return component;
}

// The shortest path of edges from `start` to `goal` inside one component, or empty.
std::vector<Edge> pathWithin(const std::vector<std::vector<Edge>>& out,
                             const std::vector<std::size_t>& component, std::size_t start,
                             std::size_t goal) {
  std::vector<const Edge*> reachedBy(out.size(), nullptr);
  std::vector<bool> visited(out.size(), false);
  std::deque<std::size_t> queue{start};
  visited[start] = true;
  while (!queue.empty() && !visited[goal]) {
    const std::size_t node = queue.front();
    queue.pop_front();
    for (const Edge& edge : out[node]) {
      if (visited[edge.to] || component[edge.to] != component[start]) continue;
      visited[edge.to] = true;
      reachedBy[edge.to] = &edge;
      queue.push_back(edge.to);
    }
  }
  std::vector<Edge> path;
  if (!visited[goal]) return path;
  for (std::size_t node = goal; node != start; node = reachedBy[node]->from) {
    path.push_back(*reachedBy[node]);
  }
  std::reverse(path.begin(), path.end());
  return path;
}

}  // namespace

void checkCycles(Validation& v) {
  const std::vector<std::vector<Edge>> out = blockingGraph(v);
  const std::vector<std::size_t> component = components(out);

  // Each cycle is named from its first connection in the file, one report per component.
  std::vector<Edge> edges;
  for (const auto& nodeEdges : out) edges.insert(edges.end(), nodeEdges.begin(), nodeEdges.end());
  std::sort(edges.begin(), edges.end(),
            [](const Edge& a, const Edge& b) { return a.connection < b.connection; });
  std::vector<bool> reported(out.size(), false);
  for (const Edge& first : edges) {
    const std::size_t which = component[first.from];
    if (component[first.to] != which || reported[which]) continue;
    reported[which] = true;
    std::vector<Edge> cycle{first};
    if (first.to != first.from) {
      const std::vector<Edge> back = pathWithin(out, component, first.to, first.from);
      cycle.insert(cycle.end(), back.begin(), back.end());
    }
    std::string names;
    for (const Edge& edge : cycle) {
      const Connection& connection = v.app.connections[edge.connection];
      if (!names.empty()) names += ", ";
      names += toString(connection.from) + " -> " + toString(connection.to);
    }
    v.error(v.app.connections[first.connection].loc,
            "cycle without initial message (would deadlock): " + names +
                "; give one of its module inputs initial-messages=\"1\" or put an 'initial' "
                "filter on it");
  }
}

}  // namespace vrflow::app::detail
