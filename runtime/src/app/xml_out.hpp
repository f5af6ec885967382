#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/model.hpp"

namespace vrflow::app::detail {

/// Appends an attribute value escaped for a double-quoted attribute: `& < > "`, and newline,
/// carriage return and tab (XML attribute normalisation would turn them into spaces).
void appendEscaped(std::string& out, std::string_view value);

/// Builds one element line of canonical output: `<name a="1" b="2"` then "/>" or ">".
class Tag {
 public:
  Tag(std::string& out, int depth, std::string_view name);
  Tag& attribute(std::string_view name, std::string_view value);
  Tag& attributeUnless(std::string_view name, std::string_view value, std::string_view omitted) {
    if (value != omitted) attribute(name, value);
    return *this;
  }
  void close() { out_ += "/>\n"; }
  /// Ends the start tag and appends `content` as escaped character data (no end tag).
  void text(std::string_view content);
  void open() { out_ += ">\n"; }

 private:
  std::string& out_;
};

/// Appends `</name>` at `depth` (2 spaces per level) and a newline.
void closeTag(std::string& out, int depth, std::string_view name);

/// Appends each comment as `<!--text-->` on its own line at `depth`.
void writeComments(std::string& out, int depth, const std::vector<std::string>& comments);

/// Appends one `<param>` line per parameter at `depth`, each after its comments.
void writeParams(std::string& out, int depth, const std::vector<Param>& params);

/// Appends the comments before section `name` of `app` and its start tag, at depth 1.
void openSection(std::string& out, const Application& app, std::string_view name);
/// Appends the comments at the end of section `name` of `app` and its end tag, at depth 1.
void closeSection(std::string& out, const Application& app, std::string_view name);

}  // namespace vrflow::app::detail
