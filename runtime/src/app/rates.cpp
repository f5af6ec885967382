// iterationRates(): how many iterations each module runs per outer iteration, from the
// repeat and decimate filters between it and the network's sources (docs/filters.md).
#include <algorithm>
#include <charconv>
#include <map>
#include <numeric>

#include "vrflow/app/graph.hpp"

namespace vrflow::app {
namespace {

constexpr uint64_t kMaxRate = uint64_t{1} << 20;

IterationRate reduced(uint64_t numerator, uint64_t denominator) {
  const uint64_t g = std::gcd(numerator, denominator);
  return {numerator / g, denominator / g};
}

bool less(const IterationRate& a, const IterationRate& b) {
  return static_cast<unsigned __int128>(a.numerator) * b.denominator <
         static_cast<unsigned __int128>(b.numerator) * a.denominator;
}

uint64_t countOf(const Filter& filter) {
  for (const Param& p : filter.params) {
    if (p.name != "count") continue;
    uint64_t value = 0;
    const auto [end, error] =
        std::from_chars(p.value.data(), p.value.data() + p.value.size(), value);
    if (error == std::errc() && end == p.value.data() + p.value.size() && value >= 1) return value;
    return 1;  // invalid: validate() reports it
  }
  return 10;  // the catalog's default
}

}  // namespace

uint64_t IterationRate::scale(uint64_t outer) const {
  if (outer == 0) return 0;
  const unsigned __int128 total =
      (static_cast<unsigned __int128>(outer) * numerator + denominator - 1) / denominator;
  if (total > UINT64_MAX) return UINT64_MAX;
  return total == 0 ? 1 : static_cast<uint64_t>(total);
}

std::vector<IterationRate> iterationRates(const Application& app, const ResolvedGraph& graph) {
  // Every node (module or filter) and what its output rate is made of.
  struct Node {
    uint64_t multiply = 1, divide = 1;
    bool hasInputs = false;
    bool known = false;
    IterationRate rate;  // of what the node runs (its inputs' fastest)
  };
  std::map<std::string, Node, std::less<>> nodes;
  for (const Module& m : app.modules) nodes[m.id];
  for (const Filter& f : app.filters) {
    Node& node = nodes[f.id];
    if (f.type == "repeat") node.multiply = countOf(f);
    if (f.type == "decimate") node.divide = countOf(f);
  }
  for (const PortEdges& input : graph.inputs) {
    if (auto it = nodes.find(input.node); it != nodes.end()) it->second.hasInputs = true;
  }
  for (auto& [id, node] : nodes) {
    if (!node.hasInputs) node.known = true;
  }
  // Relax: a node runs at the fastest rate its known producers send. Rates only grow, and a
  // graph without a growing cycle settles within one pass per node.
  bool diverged = false;
  const auto relax = [&] {
    for (std::size_t pass = 0, changed = 1; changed != 0 && !diverged; ++pass) {
      if (pass > nodes.size() + 1) diverged = true;
      changed = 0;
      for (const PortEdges& input : graph.inputs) {
        auto to = nodes.find(input.node);
        if (to == nodes.end()) continue;
        for (const std::size_t c : input.connections) {
          const auto from = nodes.find(app.connections[c].from.node);
          if (from == nodes.end() || !from->second.known) continue;
          const Node& producer = from->second;
          const IterationRate sent = reduced(producer.rate.numerator * producer.multiply,
                                             producer.rate.denominator * producer.divide);
          if (sent.numerator > kMaxRate || sent.denominator > kMaxRate) diverged = true;
          if (!to->second.known || less(to->second.rate, sent)) {
            to->second.rate = sent;
            to->second.known = true;
            ++changed;
          }
        }
      }
    }
  };
  relax();
  // A closed loop that no source feeds (the demo scene: every animator waits on its
  // interactors' forces) is settled from its first module, then scaled so that its slowest
  // module runs once per outer iteration.
  for (const Module& seed : app.modules) {
    if (diverged) break;
    if (nodes.at(seed.id).known) continue;
    std::vector<std::string> before;
    for (const auto& [id, node] : nodes) {
      if (!node.known) before.push_back(id);
    }
    nodes.at(seed.id).known = true;
    relax();
    IterationRate slowest{kMaxRate, 1};
    for (const Module& m : app.modules) {
      const Node& node = nodes.at(m.id);
      if (node.known && std::find(before.begin(), before.end(), m.id) != before.end() &&
          less(node.rate, slowest)) {
        slowest = node.rate;
      }
    }
    for (const std::string& id : before) {
      Node& node = nodes.at(id);
      if (!node.known) continue;
      node.rate = reduced(node.rate.numerator * slowest.denominator,
                          node.rate.denominator * slowest.numerator);
    }
  }
  std::vector<IterationRate> rates;
  rates.reserve(app.modules.size());
  for (const Module& m : app.modules) {
    const Node& node = nodes.at(m.id);
    rates.push_back(diverged || !node.known ? IterationRate{} : node.rate);
  }
  return rates;
}

}  // namespace vrflow::app
