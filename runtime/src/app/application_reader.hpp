#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "element_reader.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/model.hpp"

namespace vrflow::app::detail {

/// Reads an application, appending structural problems to `problems` (unsorted). Malformed
/// XML gives nullopt and exactly one diagnostic. May throw std::bad_alloc.
std::optional<Application> readApplication(std::string_view xml, const std::string& fileName,
                                           std::vector<Diagnostic>& problems);

/// Reads a <param name="..." value="..."/> element.
Param readParam(const ReadContext& context, const pugi::xml_node& node);

/// Reads the <editor> section: node positions, notes and frames (ids of notes and frames must
/// be distinct; sizes above 0; colours #rrggbb).
void readEditorSection(const ReadContext& context, const pugi::xml_node& section, Application& app);

}  // namespace vrflow::app::detail
