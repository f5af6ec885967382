#include "xml_out.hpp"

namespace vrflow::app::detail {

void appendEscaped(std::string& out, std::string_view value) {
  for (const char c : value) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\n':
        out += "&#10;";
        break;
      case '\r':
        out += "&#13;";
        break;
      case '\t':
        out += "&#9;";
        break;
      default:
        out += c;
    }
  }
}

Tag::Tag(std::string& out, int depth, std::string_view name) : out_(out) {
  out_.append(static_cast<std::size_t>(depth) * 2, ' ');
  out_ += '<';
  out_ += name;
}

Tag& Tag::attribute(std::string_view name, std::string_view value) {
  out_ += ' ';
  out_ += name;
  out_ += "=\"";
  appendEscaped(out_, value);
  out_ += '"';
  return *this;
}

void closeTag(std::string& out, int depth, std::string_view name) {
  out.append(static_cast<std::size_t>(depth) * 2, ' ');
  out += "</";
  out += name;
  out += ">\n";
}

}  // namespace vrflow::app::detail
