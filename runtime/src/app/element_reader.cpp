#include "element_reader.hpp"

#include <algorithm>

#include "text_util.hpp"

namespace vrflow::app::detail {

void ReadContext::error(SourceLocation loc, std::string message) const {
  loc.attributes.clear();
  problems.push_back(Diagnostic{std::move(loc), Diagnostic::Error, std::move(message)});
}

std::string missingAttributeMessage(std::string_view element, std::string_view attribute) {
  return "required attribute '" + std::string(attribute) + "' of <" + std::string(element) +
         "> is missing or empty";
}

ElementReader::ElementReader(const ReadContext& context, const pugi::xml_node& node,
                             std::initializer_list<std::string_view> allowed)
    : context_(context), node_(node), loc_(context.source.element(node)) {
  std::vector<std::string> allowedNames(allowed.begin(), allowed.end());
  std::vector<std::string_view> seen;
  std::size_t index = 0;
  for (const pugi::xml_attribute& attribute : node.attributes()) {
    const std::string_view name = attribute.name();
    // The n-th attribute of the element is the n-th one scanned in the tag text.
    SourceLocation at = loc_;
    if (index < loc_.attributes.size()) {
      at.line = loc_.attributes[index].line;
      at.column = loc_.attributes[index].column;
    }
    ++index;
    // Namespace declarations and xsi:schemaLocation hints are for XML tools; they are allowed
    // anywhere and not kept.
    if (name.rfind("xmlns", 0) == 0 || name.rfind("xsi:", 0) == 0) continue;
    bool known = false;
    for (const std::string_view candidate : allowed) known = known || candidate == name;
    if (!known) {
      context_.error(at, "unknown attribute '" + std::string(name) + "' on " + tag() +
                             " (allowed: " + joinNames(allowedNames) + ")" +
                             didYouMean(name, allowedNames));
      continue;
    }
    if (std::find(seen.begin(), seen.end(), name) != seen.end()) {
      context_.error(at, "attribute '" + std::string(name) + "' is repeated on " + tag() +
                             " (an attribute is written once)");
    }
    seen.push_back(name);
  }
}

std::string ElementReader::tag() const {
  return "<" + std::string(node_.name()) + ">";
}

bool ElementReader::has(const char* name) const {
  return !node_.attribute(name).empty();
}

void ElementReader::errorAt(const char* attribute, std::string message) const {
  context_.error(loc_.attribute(attribute), std::move(message));
}

void ElementReader::badValue(const char* name, const std::string& value,
                             const std::string& expectation) const {
  errorAt(name, "attribute '" + std::string(name) + "' of " + tag() + " " + expectation +
                    ", got '" + value + "'");
}

std::string ElementReader::required(const char* name) const {
  std::string value = node_.attribute(name).value();
  if (value.empty()) {
    context_.error(loc_, missingAttributeMessage(node_.name(), name));
  }
  return value;
}

std::string ElementReader::text(const char* name, std::string_view fallback) const {
  return has(name) ? std::string(node_.attribute(name).value()) : std::string(fallback);
}

int ElementReader::integer(const char* name, int fallback) const {
  if (!has(name)) return fallback;
  const std::string value = node_.attribute(name).value();
  const std::optional<long long> parsed = parseInteger(value);
  if (!parsed || *parsed < -2147483647LL || *parsed > 2147483647LL) {
    badValue(name, value, "must be an integer");
    return fallback;
  }
  return static_cast<int>(*parsed);
}

std::optional<double> ElementReader::optionalNumber(const char* name) const {
  if (!has(name)) return std::nullopt;
  const std::string value = node_.attribute(name).value();
  const std::optional<double> parsed = parseFloat(value);
  if (!parsed) badValue(name, value, "must be a finite number");
  return parsed;
}

double ElementReader::number(const char* name, double fallback) const {
  return optionalNumber(name).value_or(fallback);
}

bool ElementReader::boolean(const char* name, bool fallback) const {
  if (!has(name)) return fallback;
  const std::string value = node_.attribute(name).value();
  const std::optional<bool> parsed = parseBool(value);
  if (!parsed) {
    badValue(name, value, "must be true or false");
    return fallback;
  }
  return *parsed;
}

void reportRepeatedAttributes(const ReadContext& context, const pugi::xml_node& node,
                              const SourceLocation& loc) {
  std::vector<std::string_view> seen;
  std::size_t index = 0;
  for (const pugi::xml_attribute& attribute : node.attributes()) {
    const std::string_view name = attribute.name();
    // The n-th attribute of the element is the n-th one scanned in the tag text.
    SourceLocation at = loc;
    if (index < loc.attributes.size()) {
      at.line = loc.attributes[index].line;
      at.column = loc.attributes[index].column;
    }
    ++index;
    if (std::find(seen.begin(), seen.end(), name) != seen.end()) {
      context.error(at, "attribute '" + std::string(name) + "' is repeated on <" +
                            std::string(node.name()) + "> (an attribute is written once)");
    }
    seen.push_back(name);
  }
}

void forEachChild(const ReadContext& context, const pugi::xml_node& parent,
                  const std::vector<std::string_view>& allowed,
                  const std::function<void(const pugi::xml_node&)>& read) {
  const std::vector<std::string> allowedNames(allowed.begin(), allowed.end());
  bool textReported = false;
  for (const pugi::xml_node& child : parent.children()) {
    if (child.type() == pugi::node_pcdata || child.type() == pugi::node_cdata) {
      if (!textReported) {
        context.error(context.source.node(child),
                      "unexpected text in <" + std::string(parent.name()) + ">");
        textReported = true;
      }
      continue;
    }
    if (child.type() != pugi::node_element) continue;  // comments, processing instructions
    const std::string_view name = child.name();
    bool known = false;
    for (const std::string_view candidate : allowed) known = known || candidate == name;
    if (known) {
      read(child);
      continue;
    }
    const std::string expected =
        allowedNames.empty() ? "it holds no elements" : "allowed: " + joinNames(allowedNames);
    const SourceLocation loc = context.source.element(child);
    context.error(loc, "unknown element <" + std::string(name) + "> in <" + parent.name() + "> (" +
                           expected + ")" + didYouMean(name, allowedNames));
    // Its attributes are not read, but one written twice is a mistake of its own.
    reportRepeatedAttributes(context, child, loc);
  }
}

std::vector<std::string> commentsBefore(const pugi::xml_node& node) {
  std::vector<std::string> comments;
  for (pugi::xml_node at = node.previous_sibling(); at.type() == pugi::node_comment;
       at = at.previous_sibling()) {
    comments.insert(comments.begin(), at.value());
  }
  return comments;
}

std::vector<std::string> trailingComments(const pugi::xml_node& parent) {
  const pugi::xml_node last = parent.last_child();
  if (last.type() != pugi::node_comment) return {};
  std::vector<std::string> comments = commentsBefore(last);
  comments.push_back(last.value());
  return comments;
}

std::vector<std::string> commentsAfter(const pugi::xml_node& node) {
  std::vector<std::string> comments;
  for (pugi::xml_node at = node.next_sibling(); at.type() == pugi::node_comment;
       at = at.next_sibling()) {
    comments.push_back(at.value());
  }
  return comments;
}

std::string readTextElement(const ReadContext& context, const pugi::xml_node& node) {
  std::string text;
  for (const pugi::xml_node& child : node.children()) {
    if (child.type() == pugi::node_pcdata || child.type() == pugi::node_cdata) {
      text += child.value();
    } else if (child.type() == pugi::node_element) {
      context.error(context.source.element(child), "unknown element <" + std::string(child.name()) +
                                                       "> in <" + node.name() +
                                                       "> (it holds text only)");
    }
  }
  return text;
}

Diagnostic parseFailure(const SourceText& source, const pugi::xml_parse_result& result) {
  const SourceLocation loc =
      source.at(result.offset > 0 ? static_cast<std::size_t>(result.offset) : 0);
  return Diagnostic{loc, Diagnostic::Error, result.description()};
}

bool readDocument(const SourceText& source, std::string_view rootName,
                  std::vector<Diagnostic>& problems,
                  const std::function<void(const ReadContext&, const pugi::xml_node&)>& readRoot) {
  if (std::optional<Diagnostic> problem = encodingProblem(source)) {
    problems.push_back(std::move(*problem));
    return false;
  }
  const std::string_view xml = source.text();
  pugi::xml_document document;
  const pugi::xml_parse_result parsed = document.load_buffer(
      xml.data(), xml.size(), pugi::parse_default | pugi::parse_comments, pugi::encoding_utf8);
  if (!parsed) {
    problems.push_back(parseFailure(source, parsed));
    return false;
  }
  const ReadContext context{source, problems};
  const std::string root(rootName);
  bool rootSeen = false;
  for (const pugi::xml_node& node : document.children()) {
    if (node.type() != pugi::node_element) continue;
    if (rootSeen) {
      context.error(source.element(node),
                    "unexpected element <" + std::string(node.name()) + "> after the root element");
    } else if (node.name() != root) {
      context.error(source.element(node), "root element must be <" + root + ">, found <" +
                                              std::string(node.name()) + ">");
    } else {
      readRoot(context, node);
    }
    rootSeen = true;
  }
  if (!rootSeen) context.error(source.at(0), "no root element <" + root + ">");
  return true;
}

}  // namespace vrflow::app::detail
