#pragma once

#include <deque>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/app/package.hpp"
#include "vrflow/base/result.hpp"

namespace vrflow::app {

/// The name of a node package's manifest file.
inline constexpr std::string_view kManifestFileName = "vrflow-package.xml";

/// A package that loadSearchPath() did not load because an earlier folder has a package of the
/// same name with a different manifest (an identical copy is not reported).
struct HiddenPackage {
  std::string package;
  std::string usedManifest;    ///< the manifest loaded, from the earlier folder
  std::string hiddenManifest;  ///< the manifest left out
};

/// Every module type and filter type an application may use: the node packages' manifests plus
/// the filter types that daemon::makeCatalog() fills in (declared beside their code). Pointers it
/// hands out stay valid while the catalog lives (entries are never moved or removed).
class Catalog {
 public:
  /// An empty catalog (daemon::makeCatalog() gives one with every filter type).
  Catalog();

  /// Reads one vrflow-package.xml. Fails with "FILE:LINE:COL: error: ..." lines for a bad
  /// manifest, or when its package name is already in the catalog from another file (adding
  /// the same file twice is a no-op).
  Status addPackageFile(const std::string& path);
  /// Reads a manifest from memory; `fileName` locates messages and anchors relative
  /// executables. Fails like addPackageFile().
  Status addPackageString(std::string_view xml, const std::string& fileName);
  /// Reads `dir`/vrflow-package.xml and every `dir`/*/vrflow-package.xml (sorted by folder).
  /// Reads every manifest it can and reports all failures together.
  Status addPackageDir(const std::string& dir);
  /// addPackageDir() on each folder in order, like PATH: a package already loaded from an
  /// earlier folder hides later ones with the same name (hiddenPackages() lists those whose
  /// manifest differs). Folders that do not exist are skipped.
  Status loadSearchPath(const std::vector<std::string>& dirs);
  /// The packages loadSearchPath() left out for a different one of the same name, in order.
  const std::vector<HiddenPackage>& hiddenPackages() const { return hidden_; }

  /// Registers a module type built in code; beginIt/endIt are added when missing. Fails when
  /// `package/type` is already known.
  Status addModuleType(ModuleType type);
  /// Registers a filter type built in code. Fails when the name is already known.
  Status addFilterType(FilterType type);

  /// The module type, or nullptr.
  const ModuleType* findModule(std::string_view package, std::string_view type) const;
  /// The filter type, or nullptr.
  const FilterType* findFilter(std::string_view type) const;
  /// True when at least one module type of this package is known.
  bool hasPackage(std::string_view package) const;

  /// All module types, sorted by package then type (the editor's palette).
  std::vector<const ModuleType*> moduleTypes() const;
  /// The module types of one package, sorted by type.
  std::vector<const ModuleType*> moduleTypesIn(std::string_view package) const;
  /// All filter types, sorted by name.
  std::vector<const FilterType*> filterTypes() const;
  /// The names of all packages, sorted.
  std::vector<std::string> packages() const;
  /// The manifest files read so far, in reading order.
  const std::vector<std::string>& manifestFiles() const { return manifests_; }

  /// The ports of a module instance (empty when its type is unknown).
  std::vector<PortSpec> portsOf(const Module& module) const;
  /// The ports of a filter instance (empty when its type is unknown).
  std::vector<PortSpec> portsOf(const Filter& filter) const;

 private:
  Status addPackageFileImpl(const std::string& path, bool firstWins);
  Status addPackageDirImpl(const std::string& dir, bool firstWins);

  std::deque<ModuleType> modules_;
  std::deque<FilterType> filters_;
  std::vector<std::string> manifests_;
  std::vector<std::pair<std::string, std::string>> packageFiles_;  // package -> manifest
  std::vector<HiddenPackage> hidden_;
};

/// The folders the application's `<packages>` name (packageFolderPath()), in file order; each
/// one that is not a folder is reported in `problems` as an error at its `path` attribute and
/// left out.
std::vector<std::string> packageFolders(const Application& app, std::vector<Diagnostic>& problems);

/// A warning at each package hidden by another of the same name (Catalog::hiddenPackages()),
/// naming the one used and the order of the search path.
std::vector<Diagnostic> hiddenPackageWarnings(const Catalog& catalog);

/// The directories listed in environment variable `variable` (':'-separated), in order.
std::vector<std::string> searchPathFromEnvironment(const char* variable = "VRFLOW_PACKAGE_PATH");

}  // namespace vrflow::app
