#pragma once

#include <functional>
#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "template_text.hpp"
#include "vrflow/app/expand.hpp"

namespace vrflow::app::detail {

/// The exposed ports of one expanded instance, as endpoints of the flat application.
struct InstancePorts {
  std::string composite;
  bool failed = false;  ///< not expanded: connections to it are left out (its error says why)
  /// nullopt: the port's endpoint could not be resolved (reported); connections are left out.
  std::map<std::string, std::optional<Endpoint>, std::less<>> inputs;
  std::map<std::string, std::optional<Endpoint>, std::less<>> outputs;
};

/// What connections at one level (the application, or one instance's body) may name.
struct Level {
  std::string prefix;     ///< "" for the application, "w:" inside instance w
  std::string composite;  ///< "" for the application
  std::set<std::string, std::less<>> nodes;
  std::map<std::string, InstancePorts, std::less<>> instances;
};

/// The modules, filters and connections an instance (or the application) expands to.
struct Fragment {
  std::vector<Module> modules;
  std::vector<Filter> filters;
  std::vector<Connection> connections;

  void append(Fragment&& other);
};

/// One instance being expanded.
struct Frame {
  const Composite* composite = nullptr;
  std::string prefix;  ///< "w:" (nested: "w:sub:")
  std::string host;    ///< for inner nodes without a host
  TemplateScope scope;
  std::vector<InstanceSite> sites;  ///< innermost first
  std::vector<std::string> active;  ///< composites being expanded, outermost first
};

/// Expands one application; see expandComposites().
class Expander {
 public:
  Expander(const Application& app, const CompositeSources& sources,
           std::vector<Diagnostic>& problems);

  /// The flat application.
  Application run();

 private:
  // expand.cpp: composites and instances.
  const Composite* lookup(const std::string& name, const SourceLocation& at);
  const Composite* loadFromSearchPath(const std::string& name);
  const std::vector<std::string>& knownComposites();
  InstancePorts expandInstance(const std::string& id, const std::string& composite,
                               const std::string& host, const std::vector<Param>& args,
                               const SourceLocation& at, const Frame* parent, Fragment& out);
  bool bindParams(const Composite& composite, const std::vector<Param>& args,
                  const std::string& instance, const SourceLocation& at, TemplateScope& scope);
  bool checkInstanceId(const std::string& id, const SourceLocation& at, const Level& level);

  // expand_body.cpp: an instance's body.
  InstancePorts expandBody(Frame& frame, Fragment& out);
  void walk(const std::vector<TemplateElement>& elements, Frame& frame,
            const std::function<void(const TemplateElement&)>& visit);
  void walkRepeat(const TemplateElement& repeat, Frame& frame,
                  const std::function<void(const TemplateElement&)>& visit);
  std::optional<std::map<std::string, std::string, std::less<>>> substitute(
      const TemplateElement& element, const Frame& frame);
  bool required(const TemplateElement& element,
                const std::map<std::string, std::string, std::less<>>& values, const Frame& frame,
                std::initializer_list<const char*> names);
  std::optional<long long> integerAttribute(const TemplateElement& element, const char* name,
                                            Frame& frame);
  void addModule(const TemplateElement& element, Frame& frame, Level& level, Fragment& own);
  void addFilter(const TemplateElement& element, Frame& frame, Level& level, Fragment& own);
  void addInstance(const TemplateElement& element, Frame& frame, Level& level, Fragment& nested);
  void addConnection(const TemplateElement& element, Frame& frame, const Level& level,
                     Fragment& own);
  std::optional<Endpoint> portEndpoint(const CompositePort& port, bool source, Frame& frame,
                                       const Level& level);
  std::optional<Endpoint> resolve(const Level& level, const Endpoint& endpoint, bool source,
                                  const SourceLocation& at);
  bool spend(const SourceLocation& at);

  void error(const SourceLocation& at, std::string message);

  const Application& app_;
  const CompositeSources& sources_;
  std::vector<Diagnostic>& problems_;
  std::map<std::string, std::unique_ptr<Composite>, std::less<>> loaded_;  ///< null: none
  std::set<std::string, std::less<>> badFiles_;    ///< files found but not usable (reported)
  std::optional<std::vector<std::string>> known_;  ///< names for "unknown composite" messages
  std::set<std::string, std::less<>> reported_;    ///< "file:line:column:message" of each error
  std::size_t spent_ = 0;
  /// The product of the counts of the repeats being expanded (across nested instances).
  unsigned long long repeatProduct_ = 1;
  std::size_t bytes_ = 0;  ///< attribute text made by substitution
  bool tooLarge_ = false;
};

/// A copy of `loc` that says it came through the instances of `frame`.
SourceLocation located(const SourceLocation& loc, const Frame& frame);

/// Ids inside composites and instance ids hold neither '.' nor ':'.
bool isPlainId(const std::string& id);

}  // namespace vrflow::app::detail
