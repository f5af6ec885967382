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

// Three numbers separated by spaces and/or commas.
std::optional<std::vector<std::string_view>> splitVec3(std::string_view text) {
  std::vector<std::string_view> parts;
  std::size_t p = 0;
  const auto isSeparator = [](char c) {
    return c == ',' || std::isspace(static_cast<unsigned char>(c)) != 0;
  };
  while (p < text.size()) {
    while (p < text.size() && isSeparator(text[p])) ++p;
    const std::size_t start = p;
    while (p < text.size() && !isSeparator(text[p])) ++p;
    if (p > start) parts.push_back(text.substr(start, p - start));
    if (parts.size() > 3) return std::nullopt;
  }
  if (parts.size() != 3) return std::nullopt;
  return parts;
}

constexpr detail::EnumName<ParamType> kParamTypeNames[] = {
    {ParamType::Int, "int"},       {ParamType::Float, "float"}, {ParamType::Bool, "bool"},
    {ParamType::String, "string"}, {ParamType::Enum, "enum"},   {ParamType::Vec3, "vec3"},
    {ParamType::File, "file"}};
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

std::string toString(ParamType type) {
  return detail::nameOf(kParamTypeNames, type, "string");
}

std::optional<ParamType> parseParamType(std::string_view text) {
  return detail::valueNamed(kParamTypeNames, text);
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

std::optional<std::string> checkParamValue(const ParamSpec& spec, std::string_view value) {
  const std::string got = ", got '" + std::string(value) + "'";
  switch (spec.type) {
    case ParamType::Int: {
      const std::optional<long long> parsed = detail::parseInteger(value);
      if (!parsed) return "expects an int" + got;
      return checkRange(spec, static_cast<double>(*parsed), value);
    }
    case ParamType::Float: {
      const std::optional<double> parsed = detail::parseFloat(value);
      if (!parsed) return "expects a finite float" + got;
      return checkRange(spec, *parsed, value);
    }
    case ParamType::Bool:
      if (!detail::parseBool(value)) return "expects a bool (true or false)" + got;
      return std::nullopt;
    case ParamType::Enum:
      if (std::find(spec.choices.begin(), spec.choices.end(), value) == spec.choices.end()) {
        return "expects one of " + detail::joinNames(spec.choices) + got +
               detail::didYouMean(value, spec.choices);
      }
      return std::nullopt;
    case ParamType::Vec3: {
      const auto parts = splitVec3(value);
      if (!parts) return "expects 3 numbers 'x y z'" + got;
      for (const std::string_view part : *parts) {
        const std::optional<double> parsed = detail::parseFloat(part);
        if (!parsed) return "expects 3 finite numbers 'x y z'" + got;
        if (auto outOfRange = checkRange(spec, *parsed, part)) {
          return "component " + *outOfRange;
        }
      }
      return std::nullopt;
    }
    case ParamType::String:
    case ParamType::File:
      return std::nullopt;
  }
  return std::nullopt;
}

}  // namespace vrflow::app
