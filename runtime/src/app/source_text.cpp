#include "source_text.hpp"

#include <algorithm>

namespace vrflow::app::detail {
namespace {

bool isXmlSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

bool isUtf8Continuation(char c) {
  return (static_cast<unsigned char>(c) & 0xC0U) == 0x80U;
}

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

// The attributes of the start tag whose name begins at `nameOffset`: name and byte offset.
// The document is well-formed (pugixml accepted it), so a simple scan suffices.
std::vector<std::pair<std::string, std::size_t>> scanAttributes(std::string_view text,
                                                                std::size_t nameOffset) {
  std::vector<std::pair<std::string, std::size_t>> found;
  std::size_t p = nameOffset;
  const auto atTagEnd = [&] { return p >= text.size() || text[p] == '>' || text[p] == '/'; };
  while (!atTagEnd() && !isXmlSpace(text[p])) ++p;
  for (;;) {
    while (p < text.size() && isXmlSpace(text[p])) ++p;
    if (atTagEnd()) break;
    const std::size_t start = p;
    while (p < text.size() && text[p] != '=' && !isXmlSpace(text[p]) && text[p] != '>') ++p;
    found.emplace_back(std::string(text.substr(start, p - start)), start);
    while (p < text.size() && isXmlSpace(text[p])) ++p;
    if (p >= text.size() || text[p] != '=') break;
    ++p;
    while (p < text.size() && isXmlSpace(text[p])) ++p;
    if (p >= text.size() || (text[p] != '"' && text[p] != '\'')) break;
    const char quote = text[p++];
    while (p < text.size() && text[p] != quote) ++p;
    if (p < text.size()) ++p;
  }
  return found;
}

}  // namespace

SourceText::SourceText(std::string_view text, std::string file)
    : text_(text), file_(std::move(file)) {
  lineStarts_.push_back(0);
  for (std::size_t i = 0; i < text_.size(); ++i) {
    // XML line ends: "\n", "\r\n" and a lone "\r".
    if (text_[i] == '\n' || (text_[i] == '\r' && (i + 1 >= text_.size() || text_[i + 1] != '\n'))) {
      lineStarts_.push_back(i + 1);
    }
  }
}

SourceLocation SourceText::at(std::size_t offset) const {
  offset = std::min(offset, text_.size());
  const auto next = std::upper_bound(lineStarts_.begin(), lineStarts_.end(), offset);
  const auto lineIndex = static_cast<std::size_t>(next - lineStarts_.begin()) - 1;
  std::size_t start = lineStarts_[lineIndex];
  if (lineIndex == 0 && text_.substr(0, kUtf8Bom.size()) == kUtf8Bom) {
    start = std::min(offset, kUtf8Bom.size());
  }
  int column = 1;
  for (std::size_t i = start; i < offset; ++i) {
    if (!isUtf8Continuation(text_[i])) ++column;
  }
  SourceLocation loc;
  loc.file = file_;
  loc.line = static_cast<int>(lineIndex) + 1;
  loc.column = column;
  return loc;
}

SourceLocation SourceText::node(const pugi::xml_node& node) const {
  const std::ptrdiff_t offset = node.offset_debug();
  if (offset < 0) {
    SourceLocation loc;
    loc.file = file_;
    return loc;
  }
  return at(static_cast<std::size_t>(offset));
}

SourceLocation SourceText::element(const pugi::xml_node& node) const {
  const std::ptrdiff_t offset = node.offset_debug();
  if (offset <= 0) return this->node(node);
  // offset_debug() points at the element's name; its '<' is one byte before.
  const auto nameOffset = static_cast<std::size_t>(offset);
  SourceLocation loc = at(nameOffset - 1);
  for (auto& [name, attributeOffset] : scanAttributes(text_, nameOffset)) {
    const SourceLocation attributeLoc = at(attributeOffset);
    loc.attributes.push_back({std::move(name), attributeLoc.line, attributeLoc.column});
  }
  return loc;
}

}  // namespace vrflow::app::detail
