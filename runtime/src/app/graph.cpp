#include "vrflow/app/graph.hpp"

#include <map>
#include <utility>

namespace vrflow::app {
namespace {

const PortEdges* findEdges(const std::vector<PortEdges>& all, std::string_view node,
                           std::string_view port) {
  for (const PortEdges& edges : all) {
    if (edges.node == node && edges.port == port) return &edges;
  }
  return nullptr;
}

std::vector<const PortEdges*> edgesOf(const std::vector<PortEdges>& all, std::string_view node) {
  std::vector<const PortEdges*> found;
  for (const PortEdges& edges : all) {
    if (edges.node == node) found.push_back(&edges);
  }
  return found;
}

}  // namespace

const PortEdges* ResolvedGraph::findInput(std::string_view node, std::string_view port) const {
  return findEdges(inputs, node, port);
}

const PortEdges* ResolvedGraph::findOutput(std::string_view node, std::string_view port) const {
  return findEdges(outputs, node, port);
}

std::vector<const PortEdges*> ResolvedGraph::inputsOf(std::string_view node) const {
  return edgesOf(inputs, node);
}

std::vector<const PortEdges*> ResolvedGraph::outputsOf(std::string_view node) const {
  return edgesOf(outputs, node);
}

ResolvedGraph resolveGraph(const Application& app) {
  ResolvedGraph graph;
  std::map<std::pair<std::string, std::string>, std::size_t> inputIndex;
  std::map<std::pair<std::string, std::string>, std::size_t> outputIndex;
  const auto entry = [](std::vector<PortEdges>& all,
                        std::map<std::pair<std::string, std::string>, std::size_t>& index,
                        const Endpoint& end) -> PortEdges& {
    const auto [it, added] = index.emplace(std::make_pair(end.node, end.port), all.size());
    if (added) {
      PortEdges edges;
      edges.node = end.node;
      edges.port = end.port;
      all.push_back(std::move(edges));
    }
    return all[it->second];
  };
  for (std::size_t c = 0; c < app.connections.size(); ++c) {
    const Connection& connection = app.connections[c];
    entry(graph.outputs, outputIndex, connection.from).connections.push_back(c);
    entry(graph.inputs, inputIndex, connection.to).connections.push_back(c);
  }
  for (PortEdges& input : graph.inputs) {
    if (const Module* module = findModule(app, input.node)) {
      const InputConfig config = inputConfigOrDefault(*module, input.port);
      input.initialMessages = config.initialMessages;
      input.mode = config.mode;
    }
  }
  return graph;
}

}  // namespace vrflow::app
