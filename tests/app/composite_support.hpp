#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/expand.hpp"
#include "vrflow/app/model.hpp"

namespace vrflow::app::testing {

/// tests/app/data/composites.
std::string compositeDir();
/// Sources that search tests/app/data/composites.
CompositeSources testCompositeSources();
/// Loads `xml` (named "app.xml") and expands it with testCompositeSources(); fails the test on
/// any problem.
Application expandOrFail(std::string_view xml);
/// Loads `xml` and returns every problem of loading, expanding and validating it against
/// testCatalog().
std::vector<Diagnostic> checkComposed(std::string_view xml);
/// The ids of the modules, then the filters, of an application.
std::vector<std::string> nodeIds(const Application& app);
/// "from -> to" for every connection, in order.
std::vector<std::string> connectionTexts(const Application& app);

}  // namespace vrflow::app::testing
