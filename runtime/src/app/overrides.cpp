#include "vrflow/app/overrides.hpp"

#include <optional>
#include <string_view>

namespace vrflow::app {
namespace {

// Sets `name` in `params` from the command line: the parameter keeps no place in the file.
void setFromCommandLine(std::vector<Param>& params, const std::string& name,
                        const std::string& value, const std::string& setting) {
  Param* found = nullptr;
  for (Param& param : params) {
    if (param.name == name) found = &param;
  }
  if (found == nullptr) {
    params.push_back(Param{});
    found = &params.back();
    found->name = name;
  }
  found->value = value;
  found->loc = SourceLocation("--set " + setting, 0, 0);
}

// The (ID, PARAM, VALUE) of a well-formed `ID.PARAM=VALUE`.
struct Setting {
  std::string id, name, value;
};
std::optional<Setting> parseSetting(const std::string& setting) {
  const auto equals = setting.find('=');
  const std::string_view target =
      std::string_view(setting).substr(0, equals == std::string::npos ? 0 : equals);
  const auto dot = target.rfind('.');
  if (equals == std::string::npos || dot == std::string_view::npos || dot == 0 ||
      dot + 1 == target.size()) {
    return std::nullopt;
  }
  return Setting{std::string(target.substr(0, dot)), std::string(target.substr(dot + 1)),
                 setting.substr(equals + 1)};
}

}  // namespace

void applyInstanceOverrides(Application& application, std::vector<std::string>& settings) {
  std::vector<std::string> rest;
  for (const std::string& setting : settings) {
    const auto parsed = parseSetting(setting);
    bool set = false;
    for (Instance& instance : application.instances) {
      if (!parsed || instance.id != parsed->id) continue;
      setFromCommandLine(instance.params, parsed->name, parsed->value, setting);
      set = true;
    }
    if (!set) rest.push_back(setting);
  }
  settings = std::move(rest);
}

Status applyOverrides(Application& application, const std::vector<std::string>& settings) {
  for (const std::string& setting : settings) {
    const auto parsed = parseSetting(setting);
    if (!parsed) {
      return makeError("--set '" + setting + "': expected ID.PARAM=VALUE (e.g. water.blocks=2)");
    }
    const auto& [id, name, value] = *parsed;
    bool set = false;
    for (Module& module : application.modules) {
      if (module.id != id) continue;
      setFromCommandLine(module.params, name, value, setting);
      set = true;
    }
    for (Filter& filter : application.filters) {
      if (filter.id != id) continue;
      setFromCommandLine(filter.params, name, value, setting);
      set = true;
    }
    if (!set) {
      return makeError("--set '" + setting +
                       "': the application has no module, filter or instance '" + id + "'");
    }
  }
  return {};
}

}  // namespace vrflow::app
