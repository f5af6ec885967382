#include "vrflow/app/source_location.hpp"

namespace vrflow::app {

SourceLocation SourceLocation::attribute(std::string_view name) const {
  SourceLocation loc;
  loc.file = file;
  loc.line = line;
  loc.column = column;
  loc.expandedFrom = expandedFrom;
  for (const AttributeLocation& attribute : attributes) {
    if (attribute.name == name) {
      loc.line = attribute.line;
      loc.column = attribute.column;
      break;
    }
  }
  return loc;
}

}  // namespace vrflow::app
