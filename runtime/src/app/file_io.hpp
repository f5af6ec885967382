#pragma once

#include <string>

#include "vrflow/base/result.hpp"

namespace vrflow::app::detail {

/// The whole content of a file, or an error "cannot read file (REASON)" without the path.
Result<std::string> readWholeFile(const std::string& path);

/// Writes `content` to `path` through a temporary file in the same folder renamed into place,
/// so that a reader never sees half a file.
Status writeWholeFile(const std::string& path, const std::string& content);

}  // namespace vrflow::app::detail
