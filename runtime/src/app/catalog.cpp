#include "vrflow/app/catalog.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <tuple>

#include "file_io.hpp"
#include "manifest_reader.hpp"

namespace vrflow::app {
namespace {

std::string canonicalPath(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(path, ec);
  return ec ? path : canonical.string();
}

Status joinFailures(const std::vector<std::string>& failures) {
  if (failures.empty()) return {};
  std::string message;
  for (const std::string& failure : failures) {
    if (!message.empty()) message += '\n';
    message += failure;
  }
  return makeError(std::move(message));
}

}  // namespace

Catalog::Catalog() = default;

Status Catalog::addPackageFile(const std::string& path) {
  return addPackageFileImpl(path, /*firstWins=*/false);
}

Status Catalog::addPackageString(std::string_view xml, const std::string& fileName) {
  try {
    Result<detail::PackageManifest> manifest = detail::readPackageManifest(xml, fileName);
    if (!manifest) return manifest.error();
    if (hasPackage(manifest->name)) {
      return makeError(fileName + ": error: package '" + manifest->name + "' is already loaded");
    }
    for (ModuleType& type : manifest->modules) modules_.push_back(std::move(type));
    packageFiles_.emplace_back(manifest->name, fileName);
    manifests_.push_back(fileName);
    return {};
  } catch (const std::exception& e) {
    return makeError(fileName + ": error: cannot add package (" + e.what() + ")");
  }
}

Status Catalog::addPackageFileImpl(const std::string& path, bool firstWins) {
  try {
    const std::string canonical = canonicalPath(path);
    for (const auto& [package, file] : packageFiles_) {
      if (file == canonical) return {};  // already read
    }
    Result<std::string> content = detail::readWholeFile(path);
    if (!content) return makeError(path + ": error: " + content.error().message);
    Result<detail::PackageManifest> manifest = detail::readPackageManifest(*content, path);
    if (!manifest) return manifest.error();
    for (const auto& [package, file] : packageFiles_) {
      if (package != manifest->name) continue;
      if (firstWins) {
        // A copy of the same manifest (the build tree's copy of a source folder) hides nothing.
        const Result<std::string> used = detail::readWholeFile(file);
        if (!used || *used != *content) hidden_.push_back({package, file, canonical});
        return {};
      }
      return makeError(path + ": error: package '" + package + "' is already loaded from " + file);
    }
    for (ModuleType& type : manifest->modules) modules_.push_back(std::move(type));
    packageFiles_.emplace_back(manifest->name, canonical);
    manifests_.push_back(path);
    return {};
  } catch (const std::exception& e) {
    return makeError(path + ": error: cannot add package (" + e.what() + ")");
  }
}

Status Catalog::addPackageDir(const std::string& dir) {
  return addPackageDirImpl(dir, /*firstWins=*/false);
}

Status Catalog::addPackageDirImpl(const std::string& dir, bool firstWins) {
  namespace fs = std::filesystem;
  try {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
      return makeError(dir + ": error: not a directory");
    }
    std::vector<fs::path> manifests;
    const fs::path own = fs::path(dir) / kManifestFileName;
    if (fs::is_regular_file(own, ec)) manifests.push_back(own);
    std::vector<fs::path> subfolders;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec)) {
      if (entry.is_directory(ec)) subfolders.push_back(entry.path());
    }
    std::sort(subfolders.begin(), subfolders.end());
    for (const fs::path& folder : subfolders) {
      const fs::path manifest = folder / kManifestFileName;
      if (fs::is_regular_file(manifest, ec)) manifests.push_back(manifest);
    }
    std::vector<std::string> failures;
    for (const fs::path& manifest : manifests) {
      const Status added = addPackageFileImpl(manifest.string(), firstWins);
      if (!added) failures.push_back(added.error().message);
    }
    return joinFailures(failures);
  } catch (const std::exception& e) {
    return makeError(dir + ": error: cannot scan for packages (" + e.what() + ")");
  }
}

Status Catalog::loadSearchPath(const std::vector<std::string>& dirs) {
  std::vector<std::string> failures;
  for (const std::string& dir : dirs) {
    std::error_code ec;
    if (dir.empty() || !std::filesystem::is_directory(dir, ec)) continue;
    const Status added = addPackageDirImpl(dir, /*firstWins=*/true);
    if (!added) failures.push_back(added.error().message);
  }
  return joinFailures(failures);
}

Status Catalog::addModuleType(ModuleType type) {
  if (findModule(type.package, type.type) != nullptr) {
    return makeError("module type '" + type.package + "/" + type.type + "' is already known");
  }
  detail::addImplicitPorts(type);
  modules_.push_back(std::move(type));
  return {};
}

Status Catalog::addFilterType(FilterType type) {
  if (findFilter(type.name) != nullptr) {
    return makeError("filter type '" + type.name + "' is already known");
  }
  filters_.push_back(std::move(type));
  return {};
}

const ModuleType* Catalog::findModule(std::string_view package, std::string_view type) const {
  for (const ModuleType& candidate : modules_) {
    if (candidate.package == package && candidate.type == type) return &candidate;
  }
  return nullptr;
}

const FilterType* Catalog::findFilter(std::string_view type) const {
  for (const FilterType& candidate : filters_) {
    if (candidate.name == type) return &candidate;
  }
  return nullptr;
}

bool Catalog::hasPackage(std::string_view package) const {
  return std::any_of(modules_.begin(), modules_.end(),
                     [&](const ModuleType& type) { return type.package == package; }) ||
         std::any_of(packageFiles_.begin(), packageFiles_.end(),
                     [&](const auto& entry) { return entry.first == package; });
}

std::vector<const ModuleType*> Catalog::moduleTypes() const {
  std::vector<const ModuleType*> all;
  for (const ModuleType& type : modules_) all.push_back(&type);
  std::sort(all.begin(), all.end(), [](const ModuleType* a, const ModuleType* b) {
    return std::tie(a->package, a->type) < std::tie(b->package, b->type);
  });
  return all;
}

std::vector<const ModuleType*> Catalog::moduleTypesIn(std::string_view package) const {
  std::vector<const ModuleType*> all = moduleTypes();
  all.erase(std::remove_if(all.begin(), all.end(),
                           [&](const ModuleType* type) { return type->package != package; }),
            all.end());
  return all;
}

std::vector<const FilterType*> Catalog::filterTypes() const {
  std::vector<const FilterType*> all;
  for (const FilterType& type : filters_) all.push_back(&type);
  std::sort(all.begin(), all.end(),
            [](const FilterType* a, const FilterType* b) { return a->name < b->name; });
  return all;
}

std::vector<std::string> Catalog::packages() const {
  std::vector<std::string> names;
  for (const ModuleType& type : modules_) names.push_back(type.package);
  for (const auto& entry : packageFiles_) names.push_back(entry.first);
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

std::vector<PortSpec> Catalog::portsOf(const Module& module) const {
  const ModuleType* type = findModule(module.package, module.type);
  return type ? type->ports : std::vector<PortSpec>{};
}

std::vector<PortSpec> Catalog::portsOf(const Filter& filter) const {
  const FilterType* type = findFilter(filter.type);
  return type ? type->portsFor(filter.params) : std::vector<PortSpec>{};
}

std::vector<std::string> packageFolders(const Application& app, std::vector<Diagnostic>& problems) {
  std::vector<std::string> folders;
  for (const PackageFolder& folder : app.packages) {
    const std::string path = packageFolderPath(app, folder);
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
      folders.push_back(path);
      continue;
    }
    const std::string absolute = std::filesystem::absolute(path, ec).lexically_normal().string();
    std::string message = "package folder '" + folder.path + "'";
    if (!ec && absolute != folder.path) message += " (" + absolute + ")";
    message += " is not a folder; <packages path> is taken from the application file's folder";
    problems.push_back({folder.loc.attribute("path"), Diagnostic::Error, std::move(message)});
  }
  return folders;
}

std::vector<Diagnostic> hiddenPackageWarnings(const Catalog& catalog) {
  std::vector<Diagnostic> warnings;
  for (const HiddenPackage& hidden : catalog.hiddenPackages()) {
    warnings.push_back(
        {SourceLocation(hidden.hiddenManifest, 0, 0), Diagnostic::Warning,
         "package '" + hidden.package + "' is not used: " + hidden.usedManifest +
             " comes first on the search path (--packages, the application's <packages>, "
             "$VRFLOW_PACKAGE_PATH, the installed packages)"});
  }
  return warnings;
}

std::vector<std::string> searchPathFromEnvironment(const char* variable) {
  std::vector<std::string> dirs;
  const char* value = std::getenv(variable);  // NOLINT(concurrency-mt-unsafe): read at start-up
  if (value == nullptr) return dirs;
  const std::string text = value;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find(':', start);
    if (end == std::string::npos) end = text.size();
    if (end > start) dirs.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return dirs;
}

}  // namespace vrflow::app
