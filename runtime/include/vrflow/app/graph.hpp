#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/model.hpp"

namespace vrflow::app {

/// The connections arriving at one input port (or leaving one output port) of a module or
/// filter, as indexes into Application::connections, in file order.
struct PortEdges {
  std::string node;
  std::string port;
  std::vector<std::size_t> connections;
  int initialMessages = 0;           ///< inputs of modules: from the <input> settings
  InputMode mode = InputMode::Fifo;  ///< inputs of modules: from the <input> settings
};

/// The connections of an application grouped by port: what the runtime wires up.
struct ResolvedGraph {
  /// One entry per connected input port, in the order of its first connection in the file.
  std::vector<PortEdges> inputs;
  /// One entry per connected output port, in the order of its first connection in the file.
  std::vector<PortEdges> outputs;

  /// The edges into `node.port`, or nullptr when nothing is connected there.
  const PortEdges* findInput(std::string_view node, std::string_view port) const;
  /// The edges out of `node.port`, or nullptr when nothing is connected there.
  const PortEdges* findOutput(std::string_view node, std::string_view port) const;
  /// The connected inputs of one node, in the order of `inputs`.
  std::vector<const PortEdges*> inputsOf(std::string_view node) const;
  /// The connected outputs of one node, in the order of `outputs`.
  std::vector<const PortEdges*> outputsOf(std::string_view node) const;
};

/// Groups the connections by port. Needs no catalog and does not validate: run validate()
/// first; connections naming missing nodes are grouped like the others.
ResolvedGraph resolveGraph(const Application& app);

}  // namespace vrflow::app

namespace vrflow::app {

/// A module's iterations per iteration of the network's outer loop, as a fraction.
struct IterationRate {
  uint64_t numerator = 1;
  uint64_t denominator = 1;
  /// Iterations of this module in `outer` outer iterations, rounded up (at least 1 for outer > 0).
  uint64_t scale(uint64_t outer) const;
  friend bool operator==(const IterationRate&, const IterationRate&) = default;
};

/// The rate of every module of `app` (same order as app.modules), for `--iterations N` to count
/// outer iterations: a node with no connected input runs at 1; a `repeat` of count k multiplies
/// what enters it by k, a `decimate` of count k divides it by k; every other node runs at the
/// fastest of its inputs. Cycles are settled by iterating to a fixed point; a cycle that makes
/// a rate grow without bound (a repeat fed back without its decimate), a node fed only by a
/// cycle, or a rate beyond 2^20 / 1 gets 1, the rate every module had before multi-rate.
std::vector<IterationRate> iterationRates(const Application& app, const ResolvedGraph& graph);

}  // namespace vrflow::app
