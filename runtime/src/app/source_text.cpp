#include "source_text.hpp"

#include <algorithm>
#include <cstdio>

namespace vrflow::app::detail {
namespace {

bool isXmlSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

bool isUtf8Continuation(char c) {
  return (static_cast<unsigned char>(c) & 0xC0U) == 0x80U;
}

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

// "UTF-16LE" and the like (iconv's names) when the text starts as a wide encoding does, else "".
std::string wideEncoding(std::string_view text) {
  const auto startsWith = [&](std::string_view prefix) {
    return text.substr(0, prefix.size()) == prefix;
  };
  using namespace std::string_view_literals;
  if (startsWith("\xFF\xFE\0\0"sv) || startsWith("<\0\0\0"sv)) return "UTF-32LE";
  if (startsWith("\0\0\xFE\xFF"sv) || startsWith("\0\0\0<"sv)) return "UTF-32BE";
  if (startsWith("\xFF\xFE"sv) || startsWith("<\0"sv)) return "UTF-16LE";
  if (startsWith("\xFE\xFF"sv) || startsWith("\0<"sv)) return "UTF-16BE";
  return {};
}

// The length of the valid UTF-8 sequence at `p`, or 0 (overlong forms, surrogates and code
// points past U+10FFFF are invalid).
std::size_t utf8SequenceLength(std::string_view text, std::size_t p) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char lead = byte(p);
  if (lead < 0x80U) return 1;
  std::size_t length = 0;
  unsigned char low = 0x80U, high = 0xBFU;  // the allowed range of the second byte
  if (lead >= 0xC2U && lead <= 0xDFU) {
    length = 2;
  } else if (lead >= 0xE0U && lead <= 0xEFU) {
    length = 3;
    if (lead == 0xE0U) low = 0xA0U;   // overlong
    if (lead == 0xEDU) high = 0x9FU;  // surrogates
  } else if (lead >= 0xF0U && lead <= 0xF4U) {
    length = 4;
    if (lead == 0xF0U) low = 0x90U;   // overlong
    if (lead == 0xF4U) high = 0x8FU;  // past U+10FFFF
  } else {
    return 0;
  }
  if (p + length > text.size()) return 0;
  if (byte(p + 1) < low || byte(p + 1) > high) return 0;
  for (std::size_t i = 2; i < length; ++i) {
    if (!isUtf8Continuation(text[p + i])) return 0;
  }
  return length;
}

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

std::optional<Diagnostic> encodingProblem(const SourceText& source) {
  const std::string_view text = source.text();
  if (const std::string wide = wideEncoding(text); !wide.empty()) {
    SourceLocation loc;
    loc.file = source.file();
    return Diagnostic{loc, Diagnostic::Error,
                      "the file is encoded in " + wide +
                          "; vrflow reads UTF-8 only: convert it (e.g. iconv -f " + wide +
                          " -t UTF-8)"};
  }
  for (std::size_t p = 0; p < text.size();) {
    const std::size_t length = utf8SequenceLength(text, p);
    if (length == 0) {
      char byte[8];
      std::snprintf(byte, sizeof byte, "0x%02X", static_cast<unsigned char>(text[p]));
      return Diagnostic{source.at(p), Diagnostic::Error,
                        std::string("invalid UTF-8 (byte ") + byte +
                            "); the file must be UTF-8 text (convert it, e.g. iconv -f LATIN1 "
                            "-t UTF-8)"};
    }
    p += length;
  }
  return std::nullopt;
}

}  // namespace vrflow::app::detail
