#pragma once

// What differs between two states of an application, node by node: what the canvas applies to
// its scene after an edit instead of drawing everything again.

#include <string>
#include <vector>

#include "vrflow/app/model.hpp"

namespace vrflow::editor {

/// The differences between an application `before` and `after` an edit.
struct Changes {
  std::vector<std::string> nodesAdded;    ///< ids in `after` only
  std::vector<std::string> nodesRemoved;  ///< ids in `before` only
  /// Ids in both whose element differs (type, host, parameters, inputs, composite).
  std::vector<std::string> nodesChanged;
  /// Ids in both placed elsewhere (or no longer placed) in the `<editor>` section.
  std::vector<std::string> nodesMoved;
  /// Connections ("from -> to") in `after` only, and in `before` only.
  std::vector<std::string> connectionsAdded;
  std::vector<std::string> connectionsRemoved;
  bool hostsChanged = false;  ///< ids, addresses or order of the hosts
  bool notesChanged = false;
  bool framesChanged = false;
  /// True when nothing above differs.
  bool empty() const;
};

/// What changed from `before` to `after` (source locations are ignored).
Changes diff(const app::Application& before, const app::Application& after);

/// The key of a connection in Changes: "node.port -> node.port".
std::string connectionKey(const app::Connection& connection);

/// What a composite instance expands to: how many modules, on which hosts (sorted).
struct InstanceSummary {
  int modules = 0;
  std::vector<std::string> hosts;
};

/// The summary of every instance of `app` whose composite is found (by id); empty when the
/// application has no instances or its composites cannot be expanded.
std::vector<std::pair<std::string, InstanceSummary>> instanceSummaries(const app::Application& app);

/// "5 modules on a, b" (or "on 3 hosts" past two hosts): the badge of an instance.
std::string badgeText(const InstanceSummary& summary);

}  // namespace vrflow::editor
