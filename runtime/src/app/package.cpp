#include "vrflow/app/package.hpp"

#include <algorithm>
#include <cctype>

#include "enum_names.hpp"
#include "text_util.hpp"

namespace vrflow::app {
namespace {

std::optional<std::string> checkRange(const ParamSpec& spec, double value, std::string_view text) {
  if (spec.min && value < *spec.min) {
    return "is " + std::string(text) + ", below its minimum " + detail::formatNumber(*spec.min);
  }
  if (spec.max && value > *spec.max) {
    return "is " + std::string(text) + ", above its maximum " + detail::formatNumber(*spec.max);
  }
  return std::nullopt;
}

constexpr detail::EnumName<FileAccess> kFileAccessNames[] = {{FileAccess::Input, "input"},
                                                             {FileAccess::Output, "output"}};
constexpr detail::EnumName<ModuleKind> kModuleKindNames[] = {{ModuleKind::Animator, "animator"},
                                                             {ModuleKind::Interactor, "interactor"},
                                                             {ModuleKind::Viewer, "viewer"},
                                                             {ModuleKind::Input, "input"},
                                                             {ModuleKind::Other, "other"}};

}  // namespace

const PortSpec* findPort(const std::vector<PortSpec>& ports, std::string_view name) {
  const auto it = std::find_if(ports.begin(), ports.end(),
                               [&](const PortSpec& port) { return port.name == name; });
  return it == ports.end() ? nullptr : &*it;
}

const PortSpec* ModuleType::findPort(std::string_view name) const {
  return app::findPort(ports, name);
}

const ParamSpec* ModuleType::findParam(std::string_view name) const {
  const auto it = std::find_if(params.begin(), params.end(),
                               [&](const ParamSpec& param) { return param.name == name; });
  return it == params.end() ? nullptr : &*it;
}

std::vector<PortSpec> FilterType::portsFor(const std::vector<Param>& values) const {
  return ports ? ports(values) : std::vector<PortSpec>{};
}

int FilterType::initialMessagesFor(const std::vector<Param>& values) const {
  return initialMessages ? initialMessages(values) : 0;
}

const ParamSpec* FilterType::findParam(std::string_view paramName) const {
  const auto it = std::find_if(params.begin(), params.end(),
                               [&](const ParamSpec& param) { return param.name == paramName; });
  return it == params.end() ? nullptr : &*it;
}

std::string toString(FileAccess access) {
  return detail::nameOf(kFileAccessNames, access, "");  // Unstated has no spelling
}

std::optional<FileAccess> parseFileAccess(std::string_view text) {
  return detail::valueNamed(kFileAccessNames, text);
}

std::string toString(ModuleKind kind) {
  return detail::nameOf(kModuleKindNames, kind, "other");
}

std::optional<ModuleKind> parseModuleKind(std::string_view text) {
  return detail::valueNamed(kModuleKindNames, text);
}

Result<ParamValue> parseParamValue(const ParamSpec& spec, std::string_view text) {
  if (spec.type == ParamType::Enum &&
      std::find(spec.choices.begin(), spec.choices.end(), text) == spec.choices.end()) {
    return makeError("expects one of " + detail::joinNames(spec.choices) + ", got '" +
                     std::string(text) + "'" + detail::didYouMean(text, spec.choices));
  }
  Result<ParamValue> value = vrflow::parseParamValue(spec.type, text);
  if (!value) return value;
  std::optional<std::string> outOfRange;
  if (const auto* number = std::get_if<int64_t>(&*value)) {
    outOfRange = checkRange(spec, static_cast<double>(*number), text);
  } else if (const auto* real = std::get_if<double>(&*value)) {
    outOfRange = checkRange(spec, *real, text);
  } else if (const auto* vector = std::get_if<ParamVec3>(&*value)) {
    for (const double component : *vector) {
      outOfRange = checkRange(spec, component, detail::formatNumber(component));
      if (outOfRange) {
        outOfRange = "component " + *outOfRange;
        break;
      }
    }
  }
  if (outOfRange) return makeError(*outOfRange);
  return value;
}

std::optional<std::string> checkParamValue(const ParamSpec& spec, std::string_view value) {
  const Result<ParamValue> parsed = parseParamValue(spec, value);
  if (!parsed) return parsed.error().message;
  return std::nullopt;
}

Result<Parameters> parameterSet(const std::vector<ParamSpec>& specs,
                                const std::vector<Param>& values, std::string owner) {
  Parameters parameters(std::move(owner));
  for (const Param& value : values) {
    if (std::none_of(specs.begin(), specs.end(),
                     [&](const ParamSpec& spec) { return spec.name == value.name; })) {
      return makeError(parameters.owner() + " has no parameter '" + value.name + "'");
    }
  }
  for (const ParamSpec& spec : specs) {
    const Param* set = findParam(values, spec.name);
    const std::string& text = set != nullptr ? set->value : spec.defaultValue;
    const bool needsText = spec.type == ParamType::Int || spec.type == ParamType::Float ||
                           spec.type == ParamType::Bool || spec.type == ParamType::Vec3;
    if (set == nullptr && needsText && text.empty()) {
      parameters.declare(spec.name, spec.type, std::nullopt);
      continue;
    }
    Result<ParamValue> value = parseParamValue(spec, text);
    if (!value) {
      return makeError(parameters.owner() + ": parameter '" + spec.name + "' " +
                       value.error().message);
    }
    parameters.declare(spec.name, spec.type, std::move(*value));
  }
  return parameters;
}

}  // namespace vrflow::app
