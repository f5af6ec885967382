#include "vrflow/app/package.hpp"

#include <algorithm>
#include <cctype>

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
  switch (type) {
    case ParamType::Int:
      return "int";
    case ParamType::Float:
      return "float";
    case ParamType::Bool:
      return "bool";
    case ParamType::String:
      return "string";
    case ParamType::Enum:
      return "enum";
    case ParamType::Vec3:
      return "vec3";
    case ParamType::File:
      return "file";
  }
  return "string";
}

std::optional<ParamType> parseParamType(std::string_view text) {
  for (const ParamType type : {ParamType::Int, ParamType::Float, ParamType::Bool, ParamType::String,
                               ParamType::Enum, ParamType::Vec3, ParamType::File}) {
    if (toString(type) == text) return type;
  }
  return std::nullopt;
}

std::string toString(FileAccess access) {
  switch (access) {
    case FileAccess::Input:
      return "input";
    case FileAccess::Output:
      return "output";
    case FileAccess::Unstated:
      return "";
  }
  return "";
}

std::optional<FileAccess> parseFileAccess(std::string_view text) {
  for (const FileAccess access : {FileAccess::Input, FileAccess::Output}) {
    if (toString(access) == text) return access;
  }
  return std::nullopt;
}

std::string toString(ModuleKind kind) {
  switch (kind) {
    case ModuleKind::Animator:
      return "animator";
    case ModuleKind::Interactor:
      return "interactor";
    case ModuleKind::Viewer:
      return "viewer";
    case ModuleKind::Input:
      return "input";
    case ModuleKind::Other:
      return "other";
  }
  return "other";
}

std::optional<ModuleKind> parseModuleKind(std::string_view text) {
  for (const ModuleKind kind : {ModuleKind::Animator, ModuleKind::Interactor, ModuleKind::Viewer,
                                ModuleKind::Input, ModuleKind::Other}) {
    if (toString(kind) == text) return kind;
  }
  return std::nullopt;
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
