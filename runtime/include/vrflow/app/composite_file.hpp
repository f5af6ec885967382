#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/composite.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/base/result.hpp"

namespace vrflow::app {

/// Loads a composite file (root <composite name="..." version="1">); `fileName` is used in
/// locations and messages. Problems are handled as loadApplicationString() handles them:
/// malformed XML always fails; structural problems fail the load when `problems` is null and
/// are appended to `*problems` otherwise.
Result<Composite> loadCompositeString(std::string_view xml, std::string fileName,
                                      std::vector<Diagnostic>* problems = nullptr);

/// Reads `path` and loads it as loadCompositeString() does; a file that cannot be read fails.
Result<Composite> loadCompositeFile(const std::string& path,
                                    std::vector<Diagnostic>* problems = nullptr);

/// The canonical text of a composite file (as saveApplication() writes applications): loading
/// it and saving it again gives the same bytes.
std::string saveComposite(const Composite& composite);

/// Writes saveComposite(composite) to `path` (through a temporary file renamed into place).
Status saveCompositeFile(const Composite& composite, const std::string& path);

}  // namespace vrflow::app
