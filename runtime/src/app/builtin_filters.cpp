#include "builtin_filters.hpp"

#include <algorithm>
#include <string>

namespace vrflow::app::detail {
namespace {

constexpr long long kMaxMergeInputs = 256;
constexpr long long kMaxInitialMessages = 1000000;

PortSpec filterPort(std::string name, bool isInput, std::string doc) {
  PortSpec port;
  port.name = std::move(name);
  port.isInput = isInput;
  port.required = isInput;  // a filter with an unconnected input never fires
  port.doc = std::move(doc);
  return port;
}

ParamSpec intParam(std::string name, std::string defaultValue, double min, double max,
                   std::string doc) {
  ParamSpec param;
  param.name = std::move(name);
  param.type = ParamType::Int;
  param.defaultValue = std::move(defaultValue);
  param.min = min;
  param.max = max;
  param.doc = std::move(doc);
  return param;
}

std::vector<PortSpec> inToOut(const std::vector<Param>& /*params*/) {
  return {filterPort("in", true, "messages to forward"),
          filterPort("out", false, "the forwarded messages")};
}

}  // namespace

std::vector<FilterType> builtinFilterTypes() {
  std::vector<FilterType> types;

  FilterType passthrough;
  passthrough.name = "passthrough";
  passthrough.doc = "Forwards every message from in to out unchanged.";
  passthrough.ports = inToOut;
  types.push_back(std::move(passthrough));

  FilterType merge;
  merge.name = "merge";
  merge.doc = "Waits for one message on each of in0..in{N-1} and emits their concatenation on out.";
  merge.params.push_back(
      intParam("inputs", "2", 1, static_cast<double>(kMaxMergeInputs), "number of inputs N"));
  merge.ports = [](const std::vector<Param>& params) {
    const long long count = std::clamp(paramInt(params, "inputs", 2), 1LL, kMaxMergeInputs);
    std::vector<PortSpec> ports;
    for (long long i = 0; i < count; ++i) {
      ports.push_back(filterPort("in" + std::to_string(i), true, "one of the merged inputs"));
    }
    ports.push_back(filterPort("out", false, "the merged messages"));
    return ports;
  };
  types.push_back(std::move(merge));

  FilterType initial;
  initial.name = "initial";
  initial.doc =
      "Emits `count` empty messages on out at start-up, then forwards in to out; starts a "
      "cycle of the network.";
  initial.params.push_back(intParam("count", "1", 0, static_cast<double>(kMaxInitialMessages),
                                    "messages emitted at start-up"));
  initial.ports = inToOut;
  initial.initialMessages = [](const std::vector<Param>& params) {
    return static_cast<int>(std::clamp(paramInt(params, "count", 1), 0LL, kMaxInitialMessages));
  };
  types.push_back(std::move(initial));

  FilterType broadcast;
  broadcast.name = "broadcast";
  broadcast.doc =
      "Forwards every message from in to each connection of out; chain them as a tree to "
      "reach N receivers in O(log N) steps.";
  broadcast.ports = inToOut;
  types.push_back(std::move(broadcast));

  return types;
}

}  // namespace vrflow::app::detail
