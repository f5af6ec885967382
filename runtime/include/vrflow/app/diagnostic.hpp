#pragma once

#include <string>
#include <vector>

#include "vrflow/app/source_location.hpp"

namespace vrflow::app {

/// One problem found in an application file or model, at the element or attribute at fault.
struct Diagnostic {
  enum Severity { Error, Warning };
  SourceLocation loc;
  Severity severity = Error;
  std::string message;
};

/// "FILE:LINE:COLUMN: error: MESSAGE" (or "warning:"); parts of the location that are unknown
/// (empty file, line 0, column 0) are left out. A problem inside a composite is followed by one
/// line per instance it came through, innermost first:
/// "APP.xml:12:5: note: in instance 'w' of composite 'workers'".
/// Values quoted in MESSAGE are cut to a bounded length with their length noted (boundMessage()).
std::string formatDiagnostic(const Diagnostic& diagnostic);

/// All diagnostics, formatted, one per line (each line ends with '\n').
std::string formatDiagnostics(const std::vector<Diagnostic>& diagnostics);

/// True when at least one diagnostic is an error (not only warnings).
bool hasErrors(const std::vector<Diagnostic>& diagnostics);

/// Sorts by file, line and column (stable, so problems at one place keep their order) and
/// drops exact repeats, so that each problem is reported once. A problem inside a composite
/// that several instances show is kept once, with the first instance's notes.
void sortAndDeduplicate(std::vector<Diagnostic>& diagnostics);

}  // namespace vrflow::app
