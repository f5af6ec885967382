#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/diagnostic.hpp"

namespace vrflow::app::testing {

/// The repository root: $VRFLOW_SOURCE_DIR, or the source tree the tests were built from.
std::string sourceDir();
/// tests/app/data.
std::string dataDir();
/// The catalog of tests/app/data/packages (packages core and physics) plus built-in filters.
const Catalog& testCatalog();
/// checkApplicationString() on `xml` named "app.xml" against testCatalog().
std::vector<Diagnostic> check(std::string_view xml);
/// The whole content of a file.
std::string readFile(const std::string& path);

}  // namespace vrflow::app::testing

/// Expects exactly one diagnostic, an error at LINE:COLUMN whose message contains TEXT.
#define EXPECT_ONLY_ERROR_AT(diagnostics, wantLine, wantColumn, text)                          \
  do {                                                                                         \
    const auto& found_ = (diagnostics);                                                        \
    ASSERT_EQ(found_.size(), 1u) << ::vrflow::app::formatDiagnostics(found_);                  \
    EXPECT_EQ(found_[0].severity, ::vrflow::app::Diagnostic::Error);                           \
    EXPECT_EQ(found_[0].loc.line, wantLine) << ::vrflow::app::formatDiagnostic(found_[0]);     \
    EXPECT_EQ(found_[0].loc.column, wantColumn) << ::vrflow::app::formatDiagnostic(found_[0]); \
    EXPECT_NE(found_[0].message.find(text), std::string::npos)                                 \
        << ::vrflow::app::formatDiagnostic(found_[0]);                                         \
  } while (false)
