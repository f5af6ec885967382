#include "vrflow/daemon/filter_spec.hpp"

#include <algorithm>
#include <cstdlib>

#include "vrflow/base/assert.hpp"

namespace vrflow::daemon {

app::FilterType filterType(
    std::string name, std::string doc,
    std::function<std::vector<app::PortSpec>(const std::vector<app::Param>&)> ports) {
  app::FilterType type;
  type.name = std::move(name);
  type.doc = std::move(doc);
  type.ports = std::move(ports);
  return type;
}

void declareNumberedInputs(app::FilterType& type, const std::string& inputDoc,
                           const std::string& outputDoc) {
  const app::ParamSpec inputCount =
      intParam("inputs", "2", 1, static_cast<double>(kMaxFilterPorts), "number of inputs N");
  type.params.push_back(inputCount);
  type.ports = [inputCount, inputDoc, outputDoc](const std::vector<app::Param>& params) {
    auto ports = numberedPorts("in", clampedInt(inputCount, params), true, inputDoc);
    ports.push_back(filterPort("out", false, outputDoc));
    return ports;
  };
}

app::PortSpec filterPort(std::string name, bool isInput, std::string doc) {
  app::PortSpec port;
  port.name = std::move(name);
  port.isInput = isInput;
  port.required = isInput;
  port.doc = std::move(doc);
  return port;
}

std::vector<app::PortSpec> numberedPorts(const std::string& prefix, long long count, bool isInput,
                                         const std::string& doc) {
  std::vector<app::PortSpec> ports;
  for (long long i = 0; i < count; ++i) {
    ports.push_back(filterPort(prefix + std::to_string(i), isInput, doc));
  }
  return ports;
}

std::vector<app::PortSpec> inToOut(const std::vector<app::Param>& /*params*/) {
  return {filterPort("in", true, "messages to forward"),
          filterPort("out", false, "the forwarded messages")};
}

app::ParamSpec intParam(std::string name, std::string defaultValue, double min, double max,
                        std::string doc) {
  app::ParamSpec param;
  param.name = std::move(name);
  param.type = app::ParamType::Int;
  param.defaultValue = std::move(defaultValue);
  param.min = min;
  param.max = max;
  param.doc = std::move(doc);
  return param;
}

app::ParamSpec floatParam(std::string name, std::string defaultValue, double min, double max,
                          std::string doc) {
  app::ParamSpec param =
      intParam(std::move(name), std::move(defaultValue), min, max, std::move(doc));
  param.type = app::ParamType::Float;
  return param;
}

app::ParamSpec boolParam(std::string name, std::string defaultValue, std::string doc) {
  app::ParamSpec param = stringParam(std::move(name), std::move(defaultValue), std::move(doc));
  param.type = app::ParamType::Bool;
  return param;
}

app::ParamSpec enumParam(std::string name, std::vector<std::string> choices, std::string doc) {
  app::ParamSpec param = stringParam(std::move(name), choices.front(), std::move(doc));
  param.type = app::ParamType::Enum;
  param.choices = std::move(choices);
  return param;
}

app::ParamSpec stringParam(std::string name, std::string defaultValue, std::string doc) {
  app::ParamSpec param;
  param.name = std::move(name);
  param.type = app::ParamType::String;
  param.defaultValue = std::move(defaultValue);
  param.doc = std::move(doc);
  return param;
}

std::string declaredText(const app::ParamSpec& spec, const std::vector<app::Param>& params) {
  const app::Param* given = app::findParam(params, spec.name);
  return given != nullptr ? given->value : spec.defaultValue;
}

long long clampedInt(const app::ParamSpec& spec, const std::vector<app::Param>& params) {
  VRFLOW_ASSERT(spec.type == app::ParamType::Int && spec.min && spec.max,
                "clampedInt needs an int parameter with a range");
  const long long fallback = std::strtoll(spec.defaultValue.c_str(), nullptr, 10);
  return std::clamp(app::paramInt(params, spec.name, fallback), static_cast<long long>(*spec.min),
                    static_cast<long long>(*spec.max));
}

app::ParamSpec stampsParam() {
  return stringParam("stamps", "",
                     "how user stamps combine over the joined messages: name:first|sum|min|max, "
                     "comma-separated; a stamp not listed keeps the first message's value");
}

std::optional<std::string> checkStamps(const std::vector<app::Param>& params) {
  std::string problem;
  if (!app::parseStampRules(app::paramString(params, "stamps", ""), problem)) return problem;
  return std::nullopt;
}

}  // namespace vrflow::daemon
