#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/source_location.hpp"

namespace vrflow::app {

/// One attribute of a template element, its value as written (it may hold `${...}`).
struct TemplateAttribute {
  std::string name;
  std::string value;
};

/// An element of a composite's body kept as written, substituted each time the composite is
/// instantiated: <module>, <filter>, <instance>, <connection>, their <param> and <input>
/// children, and <repeat>.
struct TemplateElement {
  std::string name;
  std::vector<TemplateAttribute> attributes;  ///< in the element's canonical order
  std::vector<TemplateElement> children;
  SourceLocation loc;

  /// The value of attribute `attribute` as written, or nullptr when it is absent.
  const std::string* find(std::string_view attribute) const;
};

/// A parameter a composite declares; an instance sets it with <param name="..." value="..."/>.
struct CompositeParam {
  std::string name;
  std::optional<std::string> defaultValue;  ///< none: every instance must set it
  std::optional<long long> min;             ///< when set, the value must be an integer >= min
  std::optional<long long> max;             ///< when set, the value must be an integer <= max
  std::string doc;
  SourceLocation loc;
};

/// A port a composite exposes. An input stands for the inner input `endpoint`, an output for
/// the inner output `endpoint`; connections to `instance.port` go there.
struct CompositePort {
  std::string name;
  std::string endpoint;  ///< "node.port" inside the composite, as written (may hold `${...}`)
  std::string doc;
  SourceLocation loc;
};

/// A sub-network packaged for reuse: modules, filters, instances of other composites and
/// connections, with parameters and exposed ports. Its body is a template: `${...}` in
/// attribute values and <repeat> elements are expanded per instance by expandComposites().
struct Composite {
  std::string name;
  std::string doc;
  std::vector<CompositeParam> params;
  std::vector<CompositePort> inputs;
  std::vector<CompositePort> outputs;
  std::vector<TemplateElement> modules;      ///< <module> and <repeat> elements
  std::vector<TemplateElement> instances;    ///< <instance> and <repeat> elements
  std::vector<TemplateElement> filters;      ///< <filter> and <repeat> elements
  std::vector<TemplateElement> connections;  ///< <connection> and <repeat> elements
  SourceLocation loc;                        ///< loc.file: the file that defines it
};

/// The suffix of a composite's own file: composite `workers` lives in `workers.vrc.xml`.
inline constexpr std::string_view kCompositeFileSuffix = ".vrc.xml";

/// The separator between an instance's id and the ids inside it: module `anim` of instance `w`
/// is `w:anim` in the expanded application ('.' cannot be used: endpoints split at the first
/// '.').
inline constexpr char kInstanceSeparator = ':';

/// The built-in template name: inside a composite's body, `${instance}` is the full id of the
/// instance being expanded (`water`, or `outer:water` when nested). A composite parameter or a
/// `<repeat>` variable cannot take this name.
inline constexpr std::string_view kInstanceTemplateName = "instance";

/// The declared parameter `name`, or nullptr.
const CompositeParam* findCompositeParam(const Composite& composite, std::string_view name);
/// The port called `name` among `ports` (a composite's inputs or outputs), or nullptr.
const CompositePort* findCompositePort(const std::vector<CompositePort>& ports,
                                       std::string_view name);

}  // namespace vrflow::app
