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

void Tag::text(std::string_view content) {
  out_ += '>';
  for (const char c : content) {
    switch (c) {
      case '&':
        out_ += "&amp;";
        break;
      case '<':
        out_ += "&lt;";
        break;
      case '>':
        out_ += "&gt;";
        break;
      case '\r':
        out_ += "&#13;";
        break;
      default:
        out_ += c;
    }
  }
}

void closeTag(std::string& out, int depth, std::string_view name) {
  out.append(static_cast<std::size_t>(depth) * 2, ' ');
  out += "</";
  out += name;
  out += ">\n";
}

}  // namespace vrflow::app::detail

namespace vrflow::app::detail {

void writeComments(std::string& out, int depth, const std::vector<std::string>& comments) {
  for (const std::string& comment : comments) {
    out.append(static_cast<std::size_t>(depth) * 2, ' ');
    out += "<!--";
    out += comment;
    out += "-->\n";
  }
}

void writeParams(std::string& out, int depth, const std::vector<Param>& params) {
  for (const Param& param : params) {
    writeComments(out, depth, param.comments);
    Tag(out, depth, "param").attribute("name", param.name).attribute("value", param.value).close();
  }
}

void openSection(std::string& out, const Application& app, std::string_view name) {
  if (const SectionComments* comments = findSectionComments(app, name)) {
    writeComments(out, 1, comments->before);
  }
  Tag(out, 1, name).open();
}

void closeSection(std::string& out, const Application& app, std::string_view name) {
  if (const SectionComments* comments = findSectionComments(app, name)) {
    writeComments(out, 2, comments->end);
  }
  closeTag(out, 1, name);
}

}  // namespace vrflow::app::detail
