#pragma once

#include <map>
#include <string>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/daemon/filter_spec.hpp"

namespace vrflow::daemon {

/// Filter types by name: the standard library (docs/filters.md), the default per-port filters
/// `port-input` and `port-output`, and what plugins add (vrflow/daemon/plugin.hpp). The daemon
/// builds its filters from it and every catalog gets its filter types from it (makeCatalog).
class FilterRegistry {
 public:
  /// The process's registry, holding the built-in filters; the daemon builds from it.
  static FilterRegistry& instance();
  /// An empty registry.
  FilterRegistry() = default;
  /// Adds `spec`. Fails when its name is empty or already registered.
  Status add(FilterSpec spec);
  /// The spec of `type`, or nullptr.
  const FilterSpec* find(const std::string& type) const;
  /// Every registered type name, sorted.
  std::vector<std::string> types() const;
  /// Adds the declaration of every type the catalog lists (FilterSpec::inCatalog) and that
  /// `catalog` lacks.
  void addTo(app::Catalog& catalog) const;

 private:
  std::map<std::string, FilterSpec> specs_;
};

/// The catalog every program and test starts from: every filter type of the process's
/// registry (the built-in ones and those of the plugins loaded so far) and no package.
app::Catalog makeCatalog();

}  // namespace vrflow::daemon
