// Catalog declarations of the routing filters: multiplex, gate, rotate, unrotate, scatter,
// gather (docs/filters.md). The daemon's implementations live in src/daemon/filters/.
#include <cmath>
#include <cstdlib>
#include <string>

#include "builtin_filters.hpp"

namespace vrflow::app::detail {
namespace {

constexpr double kMaxPorts = static_cast<double>(kMaxFilterPorts);

FilterType multiplex() {
  FilterType type;
  type.name = "multiplex";
  type.doc =
      "Forwards each message of in0..in{N-1} to out as it comes (one input after the other "
      "when several wait), renumbered: the iteration stamp counts the messages sent.";
  type.params.push_back(intParam("inputs", "2", 1, kMaxPorts, "number of inputs N"));
  type.params.push_back(
      boolParam("renumber", "true",
                "stamp each message's iteration with the count of messages sent (a "
                "copy); false forwards them untouched, by reference"));
  type.ports = [](const std::vector<Param>& params) {
    auto ports = numberedPorts("in", portCount(params, "inputs", 2), true, "messages to forward");
    ports.push_back(filterPort("out", false, "every message, in arrival order"));
    return ports;
  };
  return type;
}

FilterType gate() {
  FilterType type;
  type.name = "gate";
  type.doc =
      "Forwards in to out while open, drops in's messages while closed. Each message on open "
      "sets the state: an integer or float user stamp `open` opens when non-zero; without "
      "it, a message with at least one chunk opens and an empty one closes.";
  type.params.push_back(
      enumParam("initially", {"closed", "open"}, "the state before the first control message"));
  type.ports = [](const std::vector<Param>&) {
    return std::vector<PortSpec>{filterPort("in", true, "messages to forward or drop"),
                                 filterPort("open", true, "control messages: open or close"),
                                 filterPort("out", false, "the messages that found it open")};
  };
  return type;
}

FilterType rotate() {
  FilterType type;
  type.name = "rotate";
  type.doc =
      "Dispatches the messages of in round-robin to out0..out{N-1}: message k goes to "
      "out{k mod N} (waiting for that output when it is full), by reference.";
  type.params.push_back(intParam("outputs", "2", 1, kMaxPorts, "number of outputs N (workers)"));
  type.ports = [](const std::vector<Param>& params) {
    std::vector<PortSpec> ports{filterPort("in", true, "messages to dispatch")};
    for (auto& port : numberedPorts("out", portCount(params, "outputs", 2), false,
                                    "every N-th message, to one worker")) {
      ports.push_back(std::move(port));
    }
    return ports;
  };
  return type;
}

FilterType unrotate() {
  FilterType type;
  type.name = "unrotate";
  type.doc =
      "Puts the results of N workers fed by a rotate back in the original order on out. "
      "`iteration`: the pending message with the smallest iteration stamp goes first (ties: "
      "lower input first), once every open input has one; `round-robin`: in0, in1, ... in "
      "turn.";
  type.params.push_back(intParam("inputs", "2", 1, kMaxPorts, "number of inputs N (workers)"));
  type.params.push_back(
      enumParam("order", {"iteration", "round-robin"}, "how the original order is found back"));
  type.ports = [](const std::vector<Param>& params) {
    auto ports = numberedPorts("in", portCount(params, "inputs", 2), true, "one worker's results");
    ports.push_back(filterPort("out", false, "every result, in the original order"));
    return ports;
  };
  return type;
}

FilterType scatter() {
  FilterType type;
  type.name = "scatter";
  type.doc =
      "Splits each message of in into N parts, one per output out0..out{N-1}, each with the "
      "message's stamps (a part may be empty). `chunk`: N contiguous runs of chunks of "
      "near-equal count; `id`: chunk to out{splitmix64(id) mod N}; `type`: objects of the "
      "k-th name of `types` to out{k}, other chunks by `others`; `bounds`: objects to every "
      "slab of `axis` cut at `cuts` that their bounds (a point: its position) meet, an object "
      "without bounds in a message where its latest bounds sent it, other chunks by `others`; "
      "`size`: every raw resource cut into N parts of whole `element-size` elements, each a "
      "raw resource of the same id prefixed by its u64 offset and u64 total size.";
  type.params.push_back(intParam("outputs", "2", 1, kMaxPorts, "number of outputs N"));
  type.params.push_back(
      enumParam("by", {"chunk", "id", "type", "bounds", "size"}, "how chunks are split"));
  type.params.push_back(intParam("element-size", "1", 1, 1 << 30,
                                 "by=size: bytes per element; parts hold whole elements"));
  type.params.push_back(
      stringParam("types", "", "by=type: N object type names, comma-separated, one per output"));
  type.params.push_back(
      enumParam("axis", {"x", "y", "z"}, "by=bounds: the axis the cuts are taken along"));
  type.params.push_back(
      stringParam("cuts", "",
                  "by=bounds: N-1 strictly increasing numbers, comma-separated; out{k} is the slab "
                  "[cut{k-1}, cut{k}), out0 unbounded below, out{N-1} unbounded above"));
  type.params.push_back(enumParam("others", {"all", "drop"},
                                  "chunks not split by type, bounds or size (by=type, bounds, "
                                  "size) go to every output (all) or nowhere (drop)"));
  type.ports = [](const std::vector<Param>& params) {
    std::vector<PortSpec> ports{filterPort("in", true, "messages to split")};
    for (auto& port : numberedPorts("out", portCount(params, "outputs", 2), false,
                                    "one part of every message")) {
      ports.push_back(std::move(port));
    }
    return ports;
  };
  type.check = [](const std::vector<Param>& params) -> std::optional<std::string> {
    const std::string by = paramString(params, "by", "chunk");
    const bool byType = by == "type";
    const auto names = splitList(paramString(params, "types", ""));
    const auto cuts = splitList(paramString(params, "cuts", ""));
    if (by != "bounds" && !cuts.empty()) return "parameter 'cuts' applies only with by=\"bounds\"";
    if (by == "bounds") {
      const long long outputs = portCount(params, "outputs", 2);
      if (static_cast<long long>(cuts.size()) + 1 != outputs) {
        return "by=\"bounds\" needs N-1 numbers in 'cuts' for N outputs: " +
               std::to_string(outputs) + " outputs, " + std::to_string(cuts.size()) + " cuts";
      }
      double previous = 0;
      for (std::size_t k = 0; k < cuts.size(); ++k) {
        char* end = nullptr;
        const double v = std::strtod(cuts[k].c_str(), &end);
        if (end == cuts[k].c_str() || *end != '\0' || !std::isfinite(v)) {
          return "'cuts': '" + cuts[k] + "' is not a finite number";
        }
        if (k > 0 && v <= previous) return "'cuts' must be strictly increasing";
        previous = v;
      }
    }
    if (!byType) {
      if (!names.empty()) return "parameter 'types' applies only with by=\"type\"";
      return std::nullopt;
    }
    const long long outputs = portCount(params, "outputs", 2);
    if (static_cast<long long>(names.size()) != outputs) {
      return "by=\"type\" needs one type name in 'types' per output: " + std::to_string(outputs) +
             " outputs, " + std::to_string(names.size()) + " names";
    }
    return std::nullopt;
  };
  return type;
}

FilterType gather() {
  FilterType type;
  type.name = "gather";
  type.doc =
      "Joins the parts made by a scatter: one message from each of in0..in{N-1}, chunks "
      "concatenated in input order (the semantics of merge).";
  type.params.push_back(intParam("inputs", "2", 1, kMaxPorts, "number of inputs N"));
  type.params.push_back(stampsParam());
  type.ports = [](const std::vector<Param>& params) {
    auto ports = numberedPorts("in", portCount(params, "inputs", 2), true, "one part");
    ports.push_back(filterPort("out", false, "the joined messages"));
    return ports;
  };
  type.check = checkStamps;
  return type;
}

}  // namespace

void addRoutingFilterTypes(std::vector<FilterType>& types) {
  types.push_back(multiplex());
  types.push_back(gate());
  types.push_back(rotate());
  types.push_back(unrotate());
  types.push_back(scatter());
  types.push_back(gather());
}

}  // namespace vrflow::app::detail
