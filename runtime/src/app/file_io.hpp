#pragma once

#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "vrflow/app/diagnostic.hpp"
#include "vrflow/base/result.hpp"

namespace vrflow::app::detail {

/// The whole content of a description file (application, manifest, composite): a regular file of
/// at most kMaxDescriptionFileBytes, or an error "cannot read file (REASON)" without the path.
Result<std::string> readWholeFile(const std::string& path);

/// Writes `content` to `path` through a temporary file in the same folder renamed into place,
/// so that a reader never sees half a file.
Status writeWholeFile(const std::string& path, const std::string& content);

/// The common end of every loader: a reader's result and the problems it found become either
/// the value (problems handed to the caller's list, if any) or one error listing them all.
/// `read` may throw; `what` names the kind of file in that message.
template <typename T, typename Read>
Result<T> finishLoad(Read read, const std::string& fileName, const char* what,
                     std::vector<Diagnostic>* problems) {
  try {
    std::vector<Diagnostic> found;
    std::optional<T> value = read(found);
    if (!value) return makeError(formatDiagnostic(found.front()));
    sortAndDeduplicate(found);
    if (problems != nullptr) {
      problems->insert(problems->end(), found.begin(), found.end());
    } else if (!found.empty()) {
      std::string message = formatDiagnostics(found);
      message.pop_back();  // the final newline
      return makeError(std::move(message));
    }
    return std::move(*value);
  } catch (const std::exception& e) {
    return makeError(fileName + ": error: cannot load " + what + " (" + e.what() + ")");
  }
}

}  // namespace vrflow::app::detail
