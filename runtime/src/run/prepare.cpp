#include "vrflow/run/prepare.hpp"

#include <algorithm>
#include <cstdio>

#include "vrflow/app/expand.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/overrides.hpp"
#include "vrflow/app/validate.hpp"
#include "vrflow/base/executable_dir.hpp"
#include "vrflow/daemon/filter_registry.hpp"
#include "vrflow/daemon/plugin.hpp"

namespace vrflow::run {

Result<app::Catalog> loadCatalog(const std::vector<std::string>& extraDirs) {
  std::vector<std::string> dirs = extraDirs;
  for (const auto& d : app::searchPathFromEnvironment()) dirs.push_back(d);
  if (const auto bin = executableDir(); !bin.empty()) {
    dirs.push_back((bin.parent_path() / "share/vrflow/packages").string());
  }
  app::Catalog catalog = daemon::makeCatalog();
  if (auto status = catalog.loadSearchPath(dirs); !status) return status.error();
  const auto plugins = daemon::filterPluginsFromEnvironment();
  if (auto status = daemon::loadFilterPlugins(plugins, catalog); !status) return status.error();
  return catalog;
}

Prepared prepare(const PrepareSettings& settings) {
  Prepared prepared;
  std::vector<app::Diagnostic>& problems = prepared.diagnostics;
  auto application = settings.text
                         ? app::loadApplicationString(*settings.text, settings.file, &problems)
                         : app::loadApplicationFile(settings.file, &problems);
  if (!application) {
    prepared.error = application.error().message;  // it names the file
    return prepared;
  }
  if (settings.validate) {
    // The command line's folders come first, then the file's own (loadCatalog adds the rest).
    std::vector<std::string> dirs = settings.packageDirs;
    for (std::string& folder : app::packageFolders(*application, problems)) {
      dirs.push_back(std::move(folder));
    }
    auto catalog = loadCatalog(dirs);
    if (!catalog) {
      prepared.error = settings.program + ": " + catalog.error().message;
      prepared.catalogFailed = true;
      return prepared;
    }
    auto hidden = app::hiddenPackageWarnings(*catalog);
    problems.insert(problems.end(), hidden.begin(), hidden.end());
    prepared.catalog = std::move(*catalog);
  }
  // Settings of the file's own composite instances change what the expansion makes.
  std::vector<std::string> moduleSettings = settings.overrides;
  app::applyInstanceOverrides(*application, moduleSettings);
  const auto sources = app::defaultCompositeSources(*application, settings.compositeDirs);
  auto flat = app::expandComposites(*application, sources, &problems);
  if (!flat) {
    prepared.error = flat.error().message;
    return prepared;
  }
  if (auto set = app::applyOverrides(*flat, moduleSettings); !set) {
    prepared.error = settings.program + ": " + set.error().message;
    return prepared;
  }
  if (prepared.catalog) {
    app::Catalog& catalog = *prepared.catalog;
    auto plugins = daemon::loadApplicationPlugins(*flat, catalog);
    problems.insert(problems.end(), plugins.begin(), plugins.end());
    auto more = app::validate(*flat, catalog);
    problems.insert(problems.end(), more.begin(), more.end());
    if (settings.files) {
      auto named = app::checkModuleFiles(*flat, catalog, *settings.files);
      problems.insert(problems.end(), named.begin(), named.end());
    }
  }
  app::sortAndDeduplicate(problems);
  if (!app::hasErrors(problems)) prepared.application = std::move(*flat);
  return prepared;
}

void printProblems(const Prepared& prepared, std::size_t maxPrinted) {
  if (!prepared.error.empty()) {
    // What was found before the error is incomplete: the error alone says what to fix first.
    std::fprintf(stderr, "%s\n", prepared.error.c_str());
    return;
  }
  const auto& problems = prepared.diagnostics;
  const std::size_t printed = std::min(problems.size(), maxPrinted);
  for (std::size_t i = 0; i < printed; ++i) {
    std::fprintf(stderr, "%s\n", app::formatDiagnostic(problems[i]).c_str());
  }
  if (problems.size() > printed) {
    std::fprintf(stderr, "... and %zu more problems\n", problems.size() - printed);
  }
}

}  // namespace vrflow::run
