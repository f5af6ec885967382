#include "vrflow/app/diagnostic.hpp"

#include <algorithm>
#include <tuple>
#include <unordered_set>

#include "vrflow/base/echo.hpp"

namespace vrflow::app {

namespace {

// "FILE:LINE:COLUMN: " without the parts that are unknown.
std::string placeText(const std::string& file, int line, int column) {
  std::string text = file;
  if (line > 0) {
    if (!text.empty()) text += ':';
    text += std::to_string(line);
    if (column > 0) text += ":" + std::to_string(column);
  }
  if (!text.empty()) text += ": ";
  return text;
}

}  // namespace

std::string formatDiagnostic(const Diagnostic& diagnostic) {
  const SourceLocation& loc = diagnostic.loc;
  std::string text = placeText(loc.file, loc.line, loc.column);
  text += diagnostic.severity == Diagnostic::Error ? "error: " : "warning: ";
  text += boundMessage(diagnostic.message);
  for (const InstanceSite& site : loc.expandedFrom) {
    text += "\n" + placeText(site.file, site.line, site.column) + "note: in instance '" +
            site.instance + "' of composite '" + site.composite + "'";
  }
  return text;
}

std::string formatDiagnostics(const std::vector<Diagnostic>& diagnostics) {
  std::string text;
  for (const Diagnostic& diagnostic : diagnostics) text += formatDiagnostic(diagnostic) + "\n";
  return text;
}

bool hasErrors(const std::vector<Diagnostic>& diagnostics) {
  return std::any_of(diagnostics.begin(), diagnostics.end(),
                     [](const Diagnostic& d) { return d.severity == Diagnostic::Error; });
}

void sortAndDeduplicate(std::vector<Diagnostic>& diagnostics) {
  const auto place = [](const Diagnostic& d) {
    return std::tie(d.loc.file, d.loc.line, d.loc.column);
  };
  std::stable_sort(diagnostics.begin(), diagnostics.end(),
                   [&](const Diagnostic& a, const Diagnostic& b) { return place(a) < place(b); });
  // Sorted by place: only diagnostics at the same place can repeat one another. A hash set of
  // the kept ones at the current place keeps this linear, however many share one place (a
  // <repeat> makes thousands).
  std::vector<Diagnostic> unique;
  unique.reserve(diagnostics.size());
  std::unordered_set<std::string> kept;  // severity and message of the kept ones at this place
  std::tuple<std::string, int, int> current{"", -1, -1};
  for (Diagnostic& diagnostic : diagnostics) {
    if (place(diagnostic) != current) {
      current = {diagnostic.loc.file, diagnostic.loc.line, diagnostic.loc.column};
      kept.clear();
    }
    std::string key = (diagnostic.severity == Diagnostic::Error ? "E" : "W") + diagnostic.message;
    if (kept.insert(std::move(key)).second) unique.push_back(std::move(diagnostic));
  }
  diagnostics = std::move(unique);
}

}  // namespace vrflow::app
