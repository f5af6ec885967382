#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"

namespace vrflow::app {

/// Loads an application from XML text; `fileName` is used in locations and messages.
///
/// Malformed XML (not well-formed) always fails with "FILE:LINE:COL: error: DESCRIPTION".
/// Structural problems of well-formed XML (unknown element or attribute, missing required
/// attribute, bad number or keyword, ...) are handled two ways:
/// - `problems == nullptr`: loading fails, the error lists every problem, one per line;
/// - `problems != nullptr`: they are appended there and loading succeeds with what could be
///   read (bad values keep their defaults), so that a caller can report them together with
///   `validate()`'s diagnostics.
/// A file without <hosts> gets one implicit host "localhost" (127.0.0.1); modules and filters
/// without a host attribute get the first host.
Result<Application> loadApplicationString(std::string_view xml, std::string fileName,
                                          std::vector<Diagnostic>* problems = nullptr);

/// Reads `path` and loads it as loadApplicationString() does; a file that cannot be read fails.
Result<Application> loadApplicationFile(const std::string& path,
                                        std::vector<Diagnostic>* problems = nullptr);

}  // namespace vrflow::app
