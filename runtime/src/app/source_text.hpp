#pragma once

#include <cstddef>
#include <optional>
#include <pugixml.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/source_location.hpp"

namespace vrflow::app::detail {

/// The text of an XML file, able to turn byte offsets into line:column locations.
class SourceText {
 public:
  /// `text` must outlive this object.
  SourceText(std::string_view text, std::string file);

  const std::string& file() const { return file_; }
  std::string_view text() const { return text_; }

  /// The location of a byte offset (clamped to the text).
  SourceLocation at(std::size_t offset) const;
  /// The location of an element's '<', with the location of each of its attributes.
  SourceLocation element(const pugi::xml_node& node) const;
  /// The location of any node (text, element) as pugixml recorded it.
  SourceLocation node(const pugi::xml_node& node) const;

 private:
  std::string_view text_;
  std::string file_;
  std::vector<std::size_t> lineStarts_;
};

/// Files are read as UTF-8: a UTF-16 or UTF-32 file (byte order mark, or NUL bytes around the
/// first '<') is named as such with how to convert it, and the first byte that is not valid
/// UTF-8 is reported at its line and column; nullopt when the text is valid UTF-8.
std::optional<Diagnostic> encodingProblem(const SourceText& source);

}  // namespace vrflow::app::detail
