#include <map>
#include <set>
#include <tuple>

#include "element_reader.hpp"
#include "text_util.hpp"
#include "validation.hpp"

namespace vrflow::app::detail {
namespace {

std::vector<std::string> portNames(const NodeInfo& node, bool inputs) {
  std::vector<std::string> names;
  for (const PortSpec& port : node.ports) {
    if (port.isInput == inputs) names.push_back(port.name);
  }
  return names;
}

// The port at one end of a connection, or nullptr after reporting why there is none (or
// silently when the node's ports are unknown: that is reported once, on the node).
const PortSpec* resolveEnd(Validation& v, const Connection& connection, bool source,
                           const NodeInfo** nodeOut) {
  const Endpoint& end = source ? connection.from : connection.to;
  const char* attribute = source ? "from" : "to";
  const SourceLocation at = connection.loc.attribute(attribute);
  *nodeOut = nullptr;
  if (end.node.empty()) {
    v.error(connection.loc, missingAttributeMessage("connection", attribute));
    return nullptr;
  }
  if (end.port.empty()) {
    v.error(at, "endpoint '" + end.node + "' must be written node.port");
    return nullptr;
  }
  const NodeInfo* node = v.find(end.node);
  if (node == nullptr) {
    const std::vector<std::string>& ids = v.nodeIds();
    const std::optional<std::string> close = closestName(end.node, ids);
    if (!source && close) v.misnamedTargets.insert(*close);
    v.error(at, "no module or filter '" + end.node + "' (known: " + joinNames(ids) + ")" +
                    (close ? "; did you mean '" + *close + "'?" : ""));
    return nullptr;
  }
  *nodeOut = node;
  if (!node->portsKnown) return nullptr;
  const PortSpec* port = findPort(node->ports, end.port);
  const std::string direction = source ? "output" : "input";
  if (!source && (port == nullptr || !port->isInput)) v.misnamedTargets.insert(node->id());
  if (port == nullptr) {
    const std::vector<std::string> names = portNames(*node, source ? false : true);
    v.error(at, node->label + " has no " + direction + " '" + end.port + "' (" + direction +
                    "s: " + joinNames(names) + ")" + didYouMean(end.port, names));
    return nullptr;
  }
  if (port->isInput == source) {
    v.error(at, "'" + toString(end) + "' is an " + (source ? "input" : "output") + " of " +
                    node->label + "; a connection goes from an output to an input");
    return nullptr;
  }
  return port;
}

// Filters forward whatever reaches them: a filter whose inputs are all fed, directly or through
// other filters, by stamps-only outputs sends stamps-only messages. Found by a fixpoint.
std::set<std::string> stampsOnlyFilters(Validation& v) {
  std::set<std::string> result;
  for (bool changed = true; changed;) {
    changed = false;
    for (const NodeInfo& node : v.nodes) {
      if (node.filter == nullptr || result.count(node.id()) != 0) continue;
      bool any = false;
      bool all = true;
      for (const Connection& c : v.app.connections) {
        if (c.to.node != node.id()) continue;
        any = true;
        const NodeInfo* from = v.find(c.from.node);
        if (from == nullptr) {
          all = false;
        } else if (from->filter != nullptr) {
          all = all && result.count(from->id()) != 0;
        } else {
          const PortSpec* port = findPort(from->ports, c.from.port);
          all = all && port != nullptr && port->stampsOnly;
        }
      }
      if (any && all) {
        result.insert(node.id());
        changed = true;
      }
    }
  }
  return result;
}

void checkPortTypes(Validation& v, const Connection& connection, const NodeInfo& fromNode,
                    const PortSpec& from, const NodeInfo& toNode, const PortSpec& to,
                    const std::set<std::string>& stampsOnly) {
  const std::string fromText = toString(connection.from);
  const std::string toText = toString(connection.to);
  if (from.data != to.data && from.data != kAnyData && to.data != kAnyData) {
    v.error(connection.loc, "port data types differ: '" + fromText + "' sends '" + from.data +
                                "' but '" + toText + "' expects '" + to.data + "'");
  }
  if (toNode.filter != nullptr || to.stampsOnly) return;  // filter inputs take both kinds
  const bool sendsStampsOnly =
      fromNode.filter != nullptr ? stampsOnly.count(fromNode.id()) != 0 : from.stampsOnly;
  if (sendsStampsOnly) {
    v.error(connection.loc,
            "'" + fromText + "' sends stamps-only messages" +
                (fromNode.filter != nullptr ? " (all its inputs are stamps-only)" : "") + " but '" +
                toText + "' expects full messages");
  }
}

void checkEachConnection(Validation& v) {
  std::map<std::tuple<std::string, std::string, std::string, std::string>, const SourceLocation*>
      seen;
  const std::set<std::string> stampsOnly = stampsOnlyFilters(v);
  for (const Connection& connection : v.app.connections) {
    const NodeInfo* fromNode = nullptr;
    const NodeInfo* toNode = nullptr;
    const PortSpec* from = resolveEnd(v, connection, /*source=*/true, &fromNode);
    const PortSpec* to = resolveEnd(v, connection, /*source=*/false, &toNode);
    if (from != nullptr && to != nullptr) {
      checkPortTypes(v, connection, *fromNode, *from, *toNode, *to, stampsOnly);
    }
    if (connection.capacity < 0) {
      v.error(connection.loc.attribute("capacity"), "capacity must not be negative, got " +
                                                        std::to_string(connection.capacity) +
                                                        " (0 means the runtime's default)");
    }
    const auto key = std::make_tuple(connection.from.node, connection.from.port, connection.to.node,
                                     connection.to.port);
    const auto [it, added] = seen.emplace(key, &connection.loc);
    if (!added) {
      v.warning(connection.loc, "duplicate connection " + toString(connection.from) + " -> " +
                                    toString(connection.to) + " (first" + atLine(*it->second) +
                                    ")");
    }
  }
}

void checkInputConfigs(Validation& v) {
  for (const Module& module : v.app.modules) {
    const NodeInfo* node = v.find(module.id);
    const bool known = node != nullptr && node->module == &module && node->portsKnown;
    for (const InputConfig& input : module.inputs) {
      if (input.initialMessages < 0) {
        v.error(
            input.loc.attribute("initial-messages"),
            "initial-messages must not be negative, got " + std::to_string(input.initialMessages));
      }
      if (input.port.empty()) {
        v.error(input.loc, missingAttributeMessage("input", "port"));
        continue;
      }
      const InputConfig* first = findInputConfig(module, input.port);
      if (first != &input) {
        v.error(input.loc, "input '" + input.port + "' of module '" + module.id +
                               "' is configured twice (first" + atLine(first->loc) + ")");
        continue;
      }
      if (!known) continue;
      const PortSpec* port = findPort(node->ports, input.port);
      if (port == nullptr) {
        const std::vector<std::string> names = portNames(*node, /*inputs=*/true);
        v.error(input.loc.attribute("port"), node->label + " has no input '" + input.port +
                                                 "' (inputs: " + joinNames(names) + ")" +
                                                 didYouMean(input.port, names));
      } else if (!port->isInput) {
        v.error(input.loc.attribute("port"), "'" + input.port + "' is an output of " + node->label +
                                                 "; <input> configures inputs");
      }
    }
  }
}

void checkRequiredInputs(Validation& v) {
  std::set<std::pair<std::string_view, std::string_view>> connected;
  for (const Connection& connection : v.app.connections) {
    connected.emplace(connection.to.node, connection.to.port);
  }
  for (const NodeInfo& node : v.nodes) {
    if (v.misnamedTargets.count(node.id()) != 0) continue;
    std::vector<std::string> unconnected;
    for (const PortSpec& port : node.ports) {
      if (!port.isInput || !port.required) continue;
      if (connected.count({node.id(), port.name}) != 0) continue;
      unconnected.push_back("'" + port.name + "'");
    }
    // One problem per node, however many inputs it has (a merge has up to 256): the number of
    // diagnostics stays bounded by the number of nodes.
    if (unconnected.size() == 1) {
      v.error(node.loc(),
              "required input " + unconnected[0] + " of " + node.label + " is not connected");
    } else if (!unconnected.empty()) {
      v.error(node.loc(), "required inputs " + joinNames(unconnected, 4) + " of " + node.label +
                              " are not connected");
    }
  }
}

}  // namespace

void checkConnections(Validation& v) {
  checkEachConnection(v);
  checkInputConfigs(v);
  checkRequiredInputs(v);
}

}  // namespace vrflow::app::detail
