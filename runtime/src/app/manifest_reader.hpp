#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/package.hpp"
#include "vrflow/base/result.hpp"

namespace vrflow::app::detail {

/// What a vrflow-package.xml declares.
struct PackageManifest {
  std::string name;
  std::string version;
  std::string doc;
  std::string file;
  std::vector<ModuleType> modules;  ///< with beginIt/endIt added, executables resolved
};

/// Parses a manifest; `fileName` locates messages and anchors relative executables. Fails with
/// one "FILE:LINE:COL: error: ..." line per problem.
Result<PackageManifest> readPackageManifest(std::string_view xml, const std::string& fileName);

/// Appends beginIt and endIt to a module type's ports when it lacks them.
void addImplicitPorts(ModuleType& type);

}  // namespace vrflow::app::detail
