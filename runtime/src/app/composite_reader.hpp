#pragma once

#include <optional>
#include <pugixml.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "element_reader.hpp"
#include "vrflow/app/model.hpp"

namespace vrflow::app::detail {

/// Reads the <composites> section of an application into app.composites.
void readComposites(const ReadContext& context, const pugi::xml_node& section, Application& app);
/// Reads the <instances> section of an application into app.instances.
void readInstances(const ReadContext& context, const pugi::xml_node& section, Application& app);

/// Reads a composite file, appending structural problems to `problems` (unsorted). Malformed
/// XML gives nullopt and exactly one diagnostic. May throw std::bad_alloc.
std::optional<Composite> readCompositeFile(std::string_view xml, const std::string& fileName,
                                           std::vector<Diagnostic>& problems);

}  // namespace vrflow::app::detail
