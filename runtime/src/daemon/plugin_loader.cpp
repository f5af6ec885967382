#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>

#include "vrflow/base/executable_dir.hpp"
#include "vrflow/daemon/plugin.hpp"

namespace vrflow::daemon {
namespace {

namespace fs = std::filesystem;

using AbiFunction = std::uint32_t (*)();

// A plugin loaded in this process: what it defines, kept to add to other catalogs.
struct LoadedPlugin {
  std::vector<app::FilterType> types;
};

std::mutex pluginsMutex;
std::map<std::string, LoadedPlugin>& loadedPlugins() {
  static std::map<std::string, LoadedPlugin> plugins;  // by canonical path
  return plugins;
}

// The entries of a ':'-separated list, empty ones dropped.
std::vector<std::string> splitPath(const char* value) {
  std::vector<std::string> entries;
  if (value == nullptr) return entries;
  std::string text(value);
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t colon = std::min(text.find(':', start), text.size());
    if (colon > start) entries.push_back(text.substr(start, colon - start));
    start = colon + 1;
  }
  return entries;
}

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

// Runs a plugin's register function into a scratch registry and catalog, so that what it
// defines is checked before the process's registry sees any of it; then adds its factories to
// the process's registry. The scratch objects hold code of the plugin: they are gone when this
// returns, so that a refused plugin can be unloaded.
Result<LoadedPlugin> registerChecked(RegisterFiltersFunction registerFilters) {
  FilterRegistry registry;
  app::Catalog catalog;
  const app::Catalog builtins;
  registerFilters(registry, catalog);

  std::set<std::string> declared;
  LoadedPlugin plugin;
  for (const app::FilterType* type : catalog.filterTypes()) {
    if (builtins.findFilter(type->name) != nullptr) continue;
    declared.insert(type->name);
    plugin.types.push_back(*type);
  }
  const std::vector<std::string> registered = registry.types();
  std::vector<std::string> problems;
  for (const auto& name : registered) {
    if (FilterRegistry::instance().find(name) != nullptr) {
      problems.push_back("filter type '" + name +
                         "' exists already (built in or from another plugin)");
    } else if (declared.count(name) == 0) {
      problems.push_back("filter type '" + name +
                         "' is registered but not declared (call catalog.addFilterType)");
    }
  }
  for (const auto& name : declared) {
    if (!std::binary_search(registered.begin(), registered.end(), name)) {
      problems.push_back("filter type '" + name +
                         "' is declared but has no factory (call registry.add)");
    }
  }
  if (registered.empty()) problems.push_back("it defines no filter type");
  if (!problems.empty()) {
    std::string message;
    for (const auto& problem : problems) message += (message.empty() ? "" : "; ") + problem;
    return makeError(message);
  }
  for (const auto& name : registered) {
    FilterRegistry::instance().add(name, *registry.find(name));
  }
  return plugin;
}

// Opens the library, checks its exports and registers what it defines. A refused library is
// unloaded; an accepted one stays loaded for good (its factories and declarations live in it).
Result<LoadedPlugin> openPlugin(const std::string& path, const std::string& label) {
  void* library = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (library == nullptr) {
    const char* why = dlerror();
    return makeError(label + ": cannot load it: " + (why != nullptr ? why : "unknown error"));
  }
  auto fail = [&](const std::string& message) -> Result<LoadedPlugin> {
    dlclose(library);
    return makeError(label + ": " + message);
  };
  auto abi = reinterpret_cast<AbiFunction>(dlsym(library, "vrflowFilterPluginAbi"));
  auto registerFilters =
      reinterpret_cast<RegisterFiltersFunction>(dlsym(library, "vrflowRegisterFilters"));
  if (abi == nullptr || registerFilters == nullptr) {
    return fail(
        "not a vrflow filter plugin: it must export vrflowFilterPluginAbi (write "
        "VRFLOW_FILTER_PLUGIN() once in its source) and extern \"C\" vrflowRegisterFilters");
  }
  if (abi() != kFilterPluginAbi) {
    return fail("built for filter plugin interface " + std::to_string(abi()) +
                ", this vrflow has " + std::to_string(kFilterPluginAbi) + "; rebuild it");
  }
  auto plugin = registerChecked(registerFilters);
  if (!plugin) return fail(plugin.error().message);
  return plugin;
}

}  // namespace

Status loadFilterPlugin(const std::string& path, app::Catalog& catalog) {
  const std::string label = "filter plugin '" + path + "'";
  std::error_code error;
  const fs::path canonical = fs::canonical(path, error);
  if (error || !fs::is_regular_file(canonical, error)) {
    return makeError(label + ": no such file");
  }
  std::lock_guard lock(pluginsMutex);
  auto& plugins = loadedPlugins();
  auto it = plugins.find(canonical.string());
  if (it == plugins.end()) {
    auto plugin = openPlugin(canonical.string(), label);
    if (!plugin) return plugin.error();
    it = plugins.emplace(canonical.string(), std::move(*plugin)).first;
  }
  for (const app::FilterType& type : it->second.types) {
    if (catalog.findFilter(type.name) != nullptr) continue;  // this plugin's, added before
    if (auto status = catalog.addFilterType(type); !status) {
      return makeError(label + ": " + status.error().message);
    }
  }
  return {};
}

std::vector<std::string> filterPluginsFromEnvironment(const char* variable) {
  std::vector<std::string> files;
  for (const auto& entry : splitPath(std::getenv(variable))) {
    std::error_code error;
    if (fs::is_regular_file(entry, error)) {
      files.push_back(entry);
    } else if (fs::is_directory(entry, error)) {
      std::vector<std::string> inFolder;
      for (const auto& file : fs::directory_iterator(entry, error)) {
        if (file.path().extension() == ".so" && file.is_regular_file(error)) {
          inFolder.push_back(file.path().string());
        }
      }
      std::sort(inFolder.begin(), inFolder.end());
      files.insert(files.end(), inFolder.begin(), inFolder.end());
    }
  }
  return files;
}

Status loadFilterPlugins(const std::vector<std::string>& paths, app::Catalog& catalog) {
  std::string failures;
  for (const auto& path : paths) {
    if (auto status = loadFilterPlugin(path, catalog); !status) {
      failures += (failures.empty() ? "" : "\n") + status.error().message;
    }
  }
  if (!failures.empty()) return makeError(failures);
  return {};
}

std::vector<app::Diagnostic> loadApplicationPlugins(const app::Application& application,
                                                    app::Catalog& catalog) {
  std::vector<std::string> dirs;
  std::error_code error;
  for (auto& entry : splitPath(std::getenv(kFilterPathVariable))) {
    if (fs::is_directory(entry, error)) dirs.push_back(std::move(entry));
  }
  if (const fs::path bin = executableDir(); !bin.empty()) {
    dirs.push_back((bin.parent_path() / "lib/vrflow/filters").string());
  }
  const fs::path appDir = fs::path(application.file).parent_path();

  std::vector<app::Diagnostic> problems;
  std::set<std::string> done;
  for (const app::Filter& filter : application.filters) {
    if (filter.plugin.empty() || !done.insert(filter.plugin).second) continue;
    const app::SourceLocation where = filter.loc.attribute("plugin");
    const fs::path named(filter.plugin);
    std::string path;
    if (named.is_absolute()) {
      path = named.string();
    } else {
      std::vector<fs::path> candidates{appDir / named};
      for (const auto& dir : dirs) candidates.push_back(fs::path(dir) / named);
      for (const auto& candidate : candidates) {
        if (fs::is_regular_file(candidate, error)) {
          path = candidate.string();
          break;
        }
      }
      if (path.empty()) {
        problems.push_back(
            {where, app::Diagnostic::Error,
             "filter plugin '" + filter.plugin +
                 "' not found (looked next to the application file and in: " + joined(dirs) + ")"});
        continue;
      }
    }
    if (auto status = loadFilterPlugin(path, catalog); !status) {
      problems.push_back({where, app::Diagnostic::Error, status.error().message});
    }
  }
  return problems;
}

}  // namespace vrflow::daemon
