#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <set>

#include "vrflow/base/assert.hpp"
#include "vrflow/base/executable_dir.hpp"
#include "vrflow/daemon/filter_registry.hpp"
#include "vrflow/daemon/plugin.hpp"

namespace vrflow::daemon {
namespace {

namespace fs = std::filesystem;

// A plugin loaded in this process: the names of the filter types it defines, kept to add them
// to other catalogs.
struct LoadedPlugin {
  std::vector<std::string> types;
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

// The ABI version of the entry point a library exports, when it is not this vrflow's: an
// entry point of another version, or the interface function of ABI 1 (before the version was
// in the entry point's name).
std::optional<std::uint32_t> otherAbiOf(void* library) {
  using LegacyAbiFunction = std::uint32_t (*)();
  if (auto legacy = reinterpret_cast<LegacyAbiFunction>(dlsym(library, "vrflowFilterPluginAbi"))) {
    return legacy();
  }
  constexpr std::uint32_t kNewerVersionsProbed = 1000;
  for (std::uint32_t abi = 1; abi <= kFilterPluginAbi + kNewerVersionsProbed; ++abi) {
    const std::string entry = kFilterPluginEntryPrefix + std::to_string(abi);
    if (abi != kFilterPluginAbi && dlsym(library, entry.c_str()) != nullptr) return abi;
  }
  return std::nullopt;
}

// What is wrong with the specs a plugin filled in (nothing: an empty string).
std::string problemsOf(const std::vector<FilterSpec>& specs) {
  std::vector<std::string> problems;
  std::set<std::string> seen;
  for (const FilterSpec& spec : specs) {
    if (spec.name().empty()) {
      problems.push_back("a filter type has an empty name");
    } else if (!seen.insert(spec.name()).second) {
      problems.push_back("filter type '" + spec.name() + "' is defined twice");
    } else if (FilterRegistry::instance().find(spec.name()) != nullptr) {
      problems.push_back("filter type '" + spec.name() +
                         "' exists already (built in or from another plugin)");
    } else if (!spec.factory) {
      problems.push_back("filter type '" + spec.name() + "' has no factory");
    }
  }
  if (specs.empty()) problems.push_back("it defines no filter type");
  std::string message;
  for (const auto& problem : problems) message += (message.empty() ? "" : "; ") + problem;
  return message;
}

// Opens the library, checks its entry point and what it defines, and adds its specs to the
// process's registry. A refused library is unloaded (its specs, which hold its code, are gone
// by then); an accepted one stays loaded for good.
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
  auto entry = reinterpret_cast<FilterPluginEntry>(dlsym(library, kFilterPluginEntry));
  if (entry == nullptr) {
    if (const auto abi = otherAbiOf(library)) {
      return fail("built for filter plugin ABI " + std::to_string(*abi) + ", this vrflow has ABI " +
                  std::to_string(kFilterPluginAbi) + " (it must export " + kFilterPluginEntry +
                  "); rebuild it against this vrflow's filter SDK");
    }
    return fail(std::string("not a vrflow filter plugin: it exports no ") + kFilterPluginEntry +
                " (write VRFLOW_FILTER_PLUGIN(specs) { ... } once in its source)");
  }
  std::string problems;
  LoadedPlugin plugin;
  {
    std::vector<FilterSpec> specs;
    entry(specs);
    problems = problemsOf(specs);
    if (problems.empty()) {
      for (FilterSpec& spec : specs) {
        plugin.types.push_back(spec.name());
        const Status added = FilterRegistry::instance().add(std::move(spec));
        VRFLOW_ASSERT(added.ok(), "a checked plugin spec joins the registry");
      }
    }
  }
  if (!problems.empty()) return fail(problems);
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
  for (const std::string& type : it->second.types) {
    if (catalog.findFilter(type) != nullptr) continue;  // this plugin's, added before
    const FilterSpec* spec = FilterRegistry::instance().find(type);
    if (auto status = catalog.addFilterType(spec->declaration); !status) {
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
