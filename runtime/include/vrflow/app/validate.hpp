#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/model.hpp"

namespace vrflow::app {

/// Every problem of an application against a catalog, sorted by line: ids, hosts, module and
/// filter types, parameters, ports and connections, unconnected required inputs, and cycles
/// that no initial message starts (they would deadlock). Each diagnostic points at the element
/// or attribute at fault. Works on models built in code too (locations then have line 0).
/// An application with composite instances is expanded first (validateWithComposites() with
/// defaultCompositeSources(app)); problems inside a composite carry the instances they came
/// through.
std::vector<Diagnostic> validate(const Application& app, const Catalog& catalog);

/// Everything wrong with an application file, in one list sorted by line: malformed XML (one
/// diagnostic), structural problems found while loading, then validate()'s findings.
std::vector<Diagnostic> checkApplicationString(std::string_view xml, const std::string& fileName,
                                               const Catalog& catalog);
/// checkApplicationString() on the contents of `path` (an unreadable file is one diagnostic).
std::vector<Diagnostic> checkApplicationFile(const std::string& path, const Catalog& catalog);

}  // namespace vrflow::app
