#pragma once

#include <functional>
#include <initializer_list>
#include <optional>
#include <pugixml.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "source_text.hpp"
#include "vrflow/app/diagnostic.hpp"

namespace vrflow::app::detail {

/// Where a reader reports structural problems.
struct ReadContext {
  const SourceText& source;
  std::vector<Diagnostic>& problems;

  void error(SourceLocation loc, std::string message) const;
};

/// Reads the attributes of one element: reports unknown, repeated, missing and badly typed
/// attributes as it goes, and remembers where each attribute is.
class ElementReader {
 public:
  /// Checks every attribute of `node` against `allowed`.
  ElementReader(const ReadContext& context, const pugi::xml_node& node,
                std::initializer_list<std::string_view> allowed);

  /// The element's location, with its attributes' locations.
  const SourceLocation& loc() const { return loc_; }
  /// True when the attribute is written.
  bool has(const char* name) const;

  /// A required attribute; reports it when missing or empty and returns "".
  std::string required(const char* name) const;
  /// An optional attribute's text, or `fallback`.
  std::string text(const char* name, std::string_view fallback = {}) const;
  /// An optional integer attribute, or `fallback` (also after reporting a bad value).
  int integer(const char* name, int fallback) const;
  /// An optional finite number, or `fallback` (also after reporting a bad value).
  double number(const char* name, double fallback) const;
  /// An optional finite number, or nullopt when absent or bad (a bad one is reported).
  std::optional<double> optionalNumber(const char* name) const;
  /// An optional xs:boolean attribute, or `fallback` (also after reporting a bad value).
  bool boolean(const char* name, bool fallback) const;
  /// An optional keyword attribute parsed by `parse`, or `fallback` after reporting a bad one;
  /// `choices` lists the keywords for the message.
  template <typename T, typename Parse>
  T keyword(const char* name, T fallback, Parse parse, std::string_view choices) const {
    if (!has(name)) return fallback;
    const std::string value = node_.attribute(name).value();
    if (const std::optional<T> parsed = parse(value)) return *parsed;
    badValue(name, value, "must be one of " + std::string(choices));
    return fallback;
  }

  /// Reports a problem with one attribute, at that attribute.
  void errorAt(const char* attribute, std::string message) const;
  /// "<name>", for messages.
  std::string tag() const;

 private:
  void badValue(const char* name, const std::string& value, const std::string& expectation) const;

  const ReadContext& context_;
  pugi::xml_node node_;
  SourceLocation loc_;
};

/// The message for a missing or empty required attribute; validate() uses the same words, so
/// that a problem found by both is reported once.
std::string missingAttributeMessage(std::string_view element, std::string_view attribute);

/// Reports each attribute of `node` written a second time, at that attribute (`loc`: the
/// element's location from SourceText::element()).
void reportRepeatedAttributes(const ReadContext& context, const pugi::xml_node& node,
                              const SourceLocation& loc);

/// Calls `read` for each child element of `parent` named in `allowed`, in order; reports text
/// and other elements as unexpected.
void forEachChild(const ReadContext& context, const pugi::xml_node& parent,
                  const std::vector<std::string_view>& allowed,
                  const std::function<void(const pugi::xml_node&)>& read);

/// The comments written just before `node`, after the element or text before it, in order.
std::vector<std::string> commentsBefore(const pugi::xml_node& node);
/// The comments written after the last element or text inside `parent`, in order.
std::vector<std::string> trailingComments(const pugi::xml_node& parent);
/// The comments written after `node`, up to the next element or text, in order.
std::vector<std::string> commentsAfter(const pugi::xml_node& node);

/// The text content of an element that holds only text (e.g. <doc>); reports child elements.
std::string readTextElement(const ReadContext& context, const pugi::xml_node& node);

/// The diagnostic for a document pugixml could not parse: its description at its offset.
Diagnostic parseFailure(const SourceText& source, const pugi::xml_parse_result& result);

/// Reads a whole document whose root must be <`rootName`>: calls `readRoot` for that root and
/// reports another root, an element after the root or no root at all. False, with the problem
/// reported, when the text is not UTF-8 or not XML (nothing was read).
bool readDocument(const SourceText& source, std::string_view rootName,
                  std::vector<Diagnostic>& problems,
                  const std::function<void(const ReadContext&, const pugi::xml_node&)>& readRoot);

}  // namespace vrflow::app::detail
