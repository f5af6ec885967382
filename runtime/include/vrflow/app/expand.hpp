#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <cstddef>
#include <string>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/composite.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"

namespace vrflow::app {

/// Where expandComposites() looks for the composite an instance names once the application's
/// own <composites> section does not define it: `composites` (already loaded, e.g. by the
/// editor), then the file NAME.vrc.xml in each folder of `searchPath`, in order.
struct CompositeSources {
  std::vector<Composite> composites;
  std::vector<std::string> searchPath;
};

/// The sources `vrflow` uses: the folder of app.file (when it was loaded from a file), then
/// `extraDirs`, then the folders of $VRFLOW_COMPOSITE_PATH (':'-separated).
CompositeSources defaultCompositeSources(const Application& app,
                                         const std::vector<std::string>& extraDirs = {});

/// Most modules, filters, connections and <repeat> iterations one expansion may make.
inline constexpr std::size_t kMaxExpandedElements = 100'000;
/// Most bytes of attribute text one expansion may make by substitution.
inline constexpr std::size_t kMaxExpandedBytes = std::size_t{64} << 20;
/// Deepest nesting of composite instances.
inline constexpr std::size_t kMaxCompositeDepth = 32;

/// The flat application the runtime runs: every instance replaced by the modules, filters and
/// connections of its composite, with ids prefixed by "INSTANCE:" (nested: "w:sub:anim"), and
/// every connection to an exposed port (`w.in`) going to the inner port it stands for. The
/// result has no composites and no instances; editor positions of instances are dropped.
/// Order: the application's own modules, filters and connections first, then each instance's
/// (its own, then its nested instances'), in file order. Elements that come from a composite
/// keep the composite file's location, with the instances they came through in
/// SourceLocation::expandedFrom.
///
/// Problems (unknown composite, bad parameter, `${...}` that cannot be evaluated, unknown inner
/// node or exposed port, composite containing itself, expansion too large) are handled as the
/// loader handles structural ones: with `problems == nullptr` they fail the expansion, listed
/// one per line; otherwise they are appended there and the result holds what could be
/// expanded (connections to an instance that failed are left out, its error says why).
Result<Application> expandComposites(const Application& app, const CompositeSources& sources,
                                     std::vector<Diagnostic>* problems = nullptr);

/// expandComposites(), then validate() of the flat application: every problem in one sorted
/// list. validate() calls it with defaultCompositeSources(app) for an application that has
/// instances.
std::vector<Diagnostic> validateWithComposites(const Application& app, const Catalog& catalog,
                                               const CompositeSources& sources);

}  // namespace vrflow::app
