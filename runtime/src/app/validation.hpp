#pragma once

#include <cstddef>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/model.hpp"

namespace vrflow::app::detail {

/// A module or filter of the application with what the catalog knows about it.
struct NodeInfo {
  const Module* module = nullptr;  ///< set for modules
  const Filter* filter = nullptr;  ///< set for filters
  const ModuleType* moduleType = nullptr;
  const FilterType* filterType = nullptr;
  /// Empty when the type is unknown, or when a parameter the ports depend on is invalid.
  std::vector<PortSpec> ports;
  /// The ports are known: the type is, and its parameters are valid (a filter's ports may
  /// depend on them, as merge's `inputs`). Connections to a node without known ports are not
  /// checked: the problem is reported once, on the node or its parameter.
  bool portsKnown = false;
  std::string label;  ///< "module 'a' (core/source)", for messages

  const std::string& id() const { return module ? module->id : filter->id; }
  const SourceLocation& loc() const { return module ? module->loc : filter->loc; }
  const std::vector<Param>& params() const { return module ? module->params : filter->params; }
};

/// The state shared by the validation passes.
class Validation {
 public:
  Validation(const Application& application, const Catalog& types);

  const Application& app;
  const Catalog& catalog;
  std::vector<Diagnostic> diagnostics;
  /// Modules then filters, in file order, each id once (its first definition).
  std::vector<NodeInfo> nodes;
  /// Nodes that a connection meant to feed but named wrongly (a bad port, or a node id close to
  /// theirs): their unconnected inputs are not reported, the bad endpoint is.
  std::set<std::string, std::less<>> misnamedTargets;

  /// The node with this id, or nullptr.
  const NodeInfo* find(std::string_view id) const;
  /// Its index in `nodes`, or nodes.size().
  std::size_t indexOf(std::string_view id) const;
  /// The ids of all nodes, in file order (for "known: ..." lists).
  const std::vector<std::string>& nodeIds() const { return ids_; }

  void error(const SourceLocation& loc, std::string message);
  void warning(const SourceLocation& loc, std::string message);

 private:
  std::map<std::string, std::size_t, std::less<>> byId_;
  std::vector<std::string> ids_;
};

/// " at line N" for a location read from a file, "" for one built in code.
std::string atLine(const SourceLocation& loc);

/// Ids, hosts, module and filter types, parameters, editor positions.
void checkNodes(Validation& validation);
/// Connection endpoints and port types, <input> settings, unconnected required inputs.
void checkConnections(Validation& validation);
/// Cycles that no initial message starts.
void checkCycles(Validation& validation);
/// MPI jobs of several modules: all on one host, none that also starts ranks of its own.
void checkMpiJobs(Validation& validation);

}  // namespace vrflow::app::detail
