#pragma once

#include <string>

#include "vrflow/app/model.hpp"

namespace vrflow::app::detail {

/// Appends the <composites> section of an application (nothing when it defines none).
void writeComposites(std::string& out, const Application& app);
/// Appends the <instances> section of an application (nothing when it has none).
void writeInstances(std::string& out, const Application& app);

}  // namespace vrflow::app::detail
