#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace vrflow::app {

/// Where one attribute of an element starts in its file (1-based line and column).
struct AttributeLocation {
  std::string name;
  int line = 0;
  int column = 0;
};

/// One composite instance an element was expanded from: where the instance is written.
struct InstanceSite {
  std::string instance;   ///< the instance's full id ("w", or "w:sub" inside instance w)
  std::string composite;  ///< the composite it instantiates
  std::string file;
  int line = 0;
  int column = 0;

  bool operator==(const InstanceSite&) const = default;
};

/// Where an element starts in its file: line and column (1-based, columns count UTF-8 code
/// points) of its '<'. Models built in code have line 0. `attributes` lets diagnostics point at
/// one attribute of the element; it is empty in diagnostics and in models built in code.
struct SourceLocation {
  SourceLocation() = default;
  /// Keeps `SourceLocation{file, line, column}` working without naming `attributes`.
  SourceLocation(std::string inFile, int inLine, int inColumn,
                 std::vector<AttributeLocation> inAttributes = {})
      : file(std::move(inFile)),
        line(inLine),
        column(inColumn),
        attributes(std::move(inAttributes)) {}

  std::string file;
  int line = 0;
  int column = 0;
  std::vector<AttributeLocation> attributes;
  /// For an element expanded from a composite (its file and line are in the composite): the
  /// instances it came through, innermost first. Empty outside composites.
  std::vector<InstanceSite> expandedFrom;

  /// The location of attribute `name` of this element, or of the element when unknown.
  SourceLocation attribute(std::string_view name) const;
};

}  // namespace vrflow::app
