#include "builtin_filters.hpp"

#include <algorithm>
#include <string>

namespace vrflow::app::detail {
namespace {

constexpr long long kMaxInitialMessages = 1000000;

}  // namespace

PortSpec filterPort(std::string name, bool isInput, std::string doc) {
  PortSpec port;
  port.name = std::move(name);
  port.isInput = isInput;
  port.required = isInput;
  port.doc = std::move(doc);
  return port;
}

std::vector<PortSpec> numberedPorts(const std::string& prefix, long long count, bool isInput,
                                    const std::string& doc) {
  std::vector<PortSpec> ports;
  for (long long i = 0; i < count; ++i) {
    ports.push_back(filterPort(prefix + std::to_string(i), isInput, doc));
  }
  return ports;
}

long long portCount(const std::vector<Param>& params, const char* name, long long fallback) {
  return std::clamp(paramInt(params, name, fallback), 1LL, kMaxFilterPorts);
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

ParamSpec floatParam(std::string name, std::string defaultValue, double min, double max,
                     std::string doc) {
  ParamSpec param = intParam(std::move(name), std::move(defaultValue), min, max, std::move(doc));
  param.type = ParamType::Float;
  return param;
}

ParamSpec boolParam(std::string name, std::string defaultValue, std::string doc) {
  ParamSpec param;
  param.name = std::move(name);
  param.type = ParamType::Bool;
  param.defaultValue = std::move(defaultValue);
  param.doc = std::move(doc);
  return param;
}

ParamSpec enumParam(std::string name, std::vector<std::string> choices, std::string doc) {
  ParamSpec param;
  param.name = std::move(name);
  param.type = ParamType::Enum;
  param.defaultValue = choices.front();
  param.choices = std::move(choices);
  param.doc = std::move(doc);
  return param;
}

ParamSpec stringParam(std::string name, std::string defaultValue, std::string doc) {
  ParamSpec param;
  param.name = std::move(name);
  param.type = ParamType::String;
  param.defaultValue = std::move(defaultValue);
  param.doc = std::move(doc);
  return param;
}

ParamSpec stampsParam() {
  return stringParam("stamps", "",
                     "how user stamps combine over the joined messages: name:first|sum|min|max, "
                     "comma-separated; a stamp not listed keeps the first message's value");
}

std::optional<std::string> checkStamps(const std::vector<Param>& params) {
  std::string problem;
  if (!parseStampRules(paramString(params, "stamps", ""), problem)) return problem;
  return std::nullopt;
}

std::vector<PortSpec> inToOut(const std::vector<Param>& /*params*/) {
  return {filterPort("in", true, "messages to forward"),
          filterPort("out", false, "the forwarded messages")};
}

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
      intParam("inputs", "2", 1, static_cast<double>(kMaxFilterPorts), "number of inputs N"));
  merge.params.push_back(stampsParam());
  merge.ports = [](const std::vector<Param>& params) {
    auto ports =
        numberedPorts("in", portCount(params, "inputs", 2), true, "one of the merged inputs");
    ports.push_back(filterPort("out", false, "the merged messages"));
    return ports;
  };
  merge.check = checkStamps;
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

  addRoutingFilterTypes(types);
  addSamplingFilterTypes(types);
  addPatternFilterTypes(types);
  return types;
}

}  // namespace vrflow::app::detail
