#pragma once

#include <vector>

#include "vrflow/app/package.hpp"

namespace vrflow::app::detail {

/// The filter types every catalog starts with: passthrough, merge, initial, broadcast.
std::vector<FilterType> builtinFilterTypes();

}  // namespace vrflow::app::detail
