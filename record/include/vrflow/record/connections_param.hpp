#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/record/format.hpp"

namespace vrflow::record {

/// The recorder's `connections` parameter: space-separated `module.port:data` entries, one per
/// recorded connection (what `vrflow record` writes; docs/recording.md). Fails on an empty
/// list, an entry without its '.' or ':', or a connection named twice.
Result<std::vector<RecordedConnection>> parseConnectionsParam(std::string_view text);
/// The parameter's text for `connections` (the inverse of parseConnectionsParam()).
std::string connectionsParam(const std::vector<RecordedConnection>& connections);

}  // namespace vrflow::record
