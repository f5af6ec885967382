#pragma once

#include <string>
#include <string_view>

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
  void open() { out_ += ">\n"; }

 private:
  std::string& out_;
};

/// Appends `</name>` at `depth` (2 spaces per level) and a newline.
void closeTag(std::string& out, int depth, std::string_view name);

}  // namespace vrflow::app::detail
