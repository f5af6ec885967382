#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <string>

#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"

namespace vrflow::app {

/// The canonical XML text of an application: UTF-8 declaration, 2-space indentation, fixed
/// attribute order, attributes with their default value left out, empty sections left out, a
/// final newline. Loading this text and saving it again gives the same bytes.
///
/// Defaults left out: a host address of 127.0.0.1, a module's or filter's host when it is the
/// first host, input `initial-messages="0"` and `mode="fifo"`, connection `capacity="0"` and
/// `policy="block"`, and the whole <hosts> section when it holds only the implicit
/// "localhost" host at 127.0.0.1.
std::string saveApplication(const Application& app);

/// Writes saveApplication(app) to `path` (through a temporary file renamed into place).
Status saveApplicationFile(const Application& app, const std::string& path);

}  // namespace vrflow::app
