#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"

namespace vrflow::app {

/// One MPI job made of several modules (a parallel module, one module per rank): the modules of
/// one package/type whose mpi-job parameter (ModuleType::mpiJobParam) has the same non-empty
/// value. Each module keeps its own ports and connections; the runtime starts them together.
struct MpiJob {
  std::string name;  ///< the parameter's value
  std::string package;
  std::string type;
  /// Indices in Application::modules, in rank order: rank r is the r-th module of the job in
  /// the application's module order.
  std::vector<std::size_t> modules;

  /// "water:b0, water:b1", for messages.
  std::string moduleIds(const Application& application) const;
};

/// The MPI jobs of a flat application (composites expanded), in the order of their first
/// modules; jobs of one module included. Modules of unknown types are left out.
std::vector<MpiJob> mpiJobs(const Application& application, const Catalog& catalog);

/// The value of parameter `name` of `module`: its own setting, else the default of its type
/// (empty when neither exists).
std::string effectiveParamValue(const Module& module, const ModuleType& type,
                                std::string_view name);

}  // namespace vrflow::app
