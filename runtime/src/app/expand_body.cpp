// Expansion of one instance's body: <repeat>, `${...}` substitution, and the modules, filters,
// instances and connections it makes, with their ids prefixed and endpoints resolved.
#include <algorithm>

#include "expansion.hpp"
#include "text_util.hpp"

namespace vrflow::app::detail {
namespace {

using Values = std::map<std::string, std::string, std::less<>>;

std::string valueOf(const Values& values, std::string_view name) {
  const auto it = values.find(name);
  return it == values.end() ? std::string() : it->second;
}

std::string mustBe(const TemplateElement& element, std::string_view attribute,
                   std::string_view expectation, std::string_view value) {
  return "attribute '" + std::string(attribute) + "' of <" + element.name + "> must be " +
         std::string(expectation) + ", got '" + std::string(value) + "'";
}

template <typename Ports>
std::vector<std::string> portNames(const Ports& ports) {
  std::vector<std::string> names;
  for (const auto& entry : ports) names.push_back(entry.first);
  return names;
}

}  // namespace

bool Expander::spend(const SourceLocation& at) {
  if (tooLarge_) return false;
  if (++spent_ <= kMaxExpandedElements) return true;
  tooLarge_ = true;
  error(at, "the expansion makes more than " + std::to_string(kMaxExpandedElements) +
                " modules, filters, connections and repeat iterations; check the repeat counts");
  return false;
}

std::optional<Values> Expander::substitute(const TemplateElement& element, const Frame& frame) {
  Values values;
  bool ok = true;
  for (const TemplateAttribute& attribute : element.attributes) {
    Result<std::string> value = substituteTemplate(attribute.value, frame.scope);
    if (!value) {
      error(
          located(element.loc, frame).attribute(attribute.name),
          "attribute '" + attribute.name + "' of <" + element.name + ">: " + value.error().message);
      ok = false;
      continue;
    }
    bytes_ += value->size();
    if (bytes_ > kMaxExpandedBytes && !tooLarge_) {
      tooLarge_ = true;
      error(located(element.loc, frame),
            "the expansion makes more than " + std::to_string(kMaxExpandedBytes >> 20) +
                " MiB of attribute text; check the repeat counts and the parameters");
    }
    if (tooLarge_) return std::nullopt;
    values[attribute.name] = std::move(*value);
  }
  if (!ok) return std::nullopt;
  return values;
}

// A required attribute written empty was reported when loading; one that becomes empty
// through substitution is reported here.
bool Expander::required(const TemplateElement& element, const Values& values, const Frame& frame,
                        std::initializer_list<const char*> names) {
  bool ok = true;
  for (const char* name : names) {
    const std::string* written = element.find(name);
    if (written == nullptr || written->empty()) {
      ok = false;
    } else if (valueOf(values, name).empty()) {
      error(located(element.loc, frame), "required attribute '" + std::string(name) + "' of <" +
                                             element.name + "> is empty once substituted ('" +
                                             *written + "')");
      ok = false;
    }
  }
  return ok;
}

std::optional<long long> Expander::integerAttribute(const TemplateElement& element,
                                                    const char* name, Frame& frame) {
  const std::string* written = element.find(name);
  if (written == nullptr || written->empty()) return std::nullopt;  // reported when loading
  const SourceLocation at = located(element.loc, frame).attribute(name);
  Result<std::string> text = substituteTemplate(*written, frame.scope);
  if (!text) {
    error(at, "attribute '" + std::string(name) + "' of <" + element.name +
                  ">: " + text.error().message);
    return std::nullopt;
  }
  const std::optional<long long> value = parseInteger(*text);
  if (!value) {
    const bool plain = written->find("${") == std::string::npos;
    error(at, mustBe(element, name, "an integer", *text) +
                  (plain ? " (write ${...} to use a parameter or an expression)" : ""));
  }
  return value;
}

void Expander::walk(const std::vector<TemplateElement>& elements, Frame& frame,
                    const std::function<void(const TemplateElement&)>& visit) {
  for (const TemplateElement& element : elements) {
    if (element.name == "repeat") {
      walkRepeat(element, frame, visit);
    } else if (spend(located(element.loc, frame))) {
      visit(element);
    }
    if (tooLarge_) return;
  }
}

void Expander::walkRepeat(const TemplateElement& repeat, Frame& frame,
                          const std::function<void(const TemplateElement&)>& visit) {
  const std::string* var = repeat.find("var");
  if (var == nullptr || !isTemplateName(*var) || *var == kInstanceTemplateName) {
    return;  // reported when loading
  }
  const SourceLocation loc = located(repeat.loc, frame);
  const std::optional<long long> count = integerAttribute(repeat, "count", frame);
  std::optional<long long> start = 0;
  if (repeat.find("start") != nullptr) start = integerAttribute(repeat, "start", frame);
  if (!count || !start) return;
  if (*count < 0) {
    error(loc.attribute("count"),
          "repeat count must not be negative, got " + std::to_string(*count));
    return;
  }
  if (frame.scope.count(*var) != 0) {
    error(loc.attribute("var"), "repeat variable '" + *var +
                                    "' hides a parameter or an enclosing repeat variable of the "
                                    "same name; rename it");
    return;
  }
  // The work is bounded before it is done: this count times those of the repeats around it (in
  // this body and the instances it is in) is how many times the body is expanded.
  unsigned long long iterations = 0;
  if (__builtin_mul_overflow(repeatProduct_, static_cast<unsigned long long>(*count),
                             &iterations) ||
      iterations > kMaxExpandedElements) {
    tooLarge_ = true;
    const bool nested = repeatProduct_ > 1;
    error(loc, "the expansion makes more than " + std::to_string(kMaxExpandedElements) +
                   " modules, filters, connections and repeat iterations: repeat count " +
                   std::to_string(*count) +
                   (nested ? " times the counts of the repeats around it" : std::string()) +
                   " is refused before expanding; check the repeat counts");
    return;
  }
  const unsigned long long enclosing = repeatProduct_;
  repeatProduct_ = std::max(iterations, 1ULL);
  for (long long k = 0; k < *count; ++k) {
    long long value = 0;
    if (__builtin_add_overflow(*start, k, &value)) {
      error(loc.attribute("start"), "repeat variable '" + *var + "' overflows 64 bits");
      break;
    }
    if (!spend(loc)) break;
    frame.scope[*var] = std::to_string(value);
    walk(repeat.children, frame, visit);
    if (tooLarge_) break;
  }
  repeatProduct_ = enclosing;
  frame.scope.erase(*var);
}

void Expander::addModule(const TemplateElement& element, Frame& frame, Level& level,
                         Fragment& own) {
  const std::optional<Values> values = substitute(element, frame);
  if (!values || !required(element, *values, frame, {"id", "package", "type"})) return;
  Module module;
  const std::string id = valueOf(*values, "id");
  module.loc = located(element.loc, frame);
  if (!isPlainId(id)) {
    error(module.loc.attribute("id"), "id '" + id + "' must not contain '.' or '" +
                                          std::string(1, kInstanceSeparator) +
                                          "' (inside a composite, ids get the instance's prefix)");
    return;
  }
  module.id = frame.prefix + id;
  module.package = valueOf(*values, "package");
  module.type = valueOf(*values, "type");
  module.host = valueOf(*values, "host");
  if (module.host.empty()) module.host = frame.host;
  if (values->count("endit") != 0) {
    const std::string text = valueOf(*values, "endit");
    if (const std::optional<EndItTiming> timing = parseEndItTiming(text)) {
      module.endIt = *timing;
    } else {
      error(module.loc.attribute("endit"),
            mustBe(element, "endit", "one of after-iteration, after-wait", text));
    }
  }
  for (const TemplateElement& child : element.children) {
    const std::optional<Values> settings = substitute(child, frame);
    if (!settings) continue;
    const SourceLocation at = located(child.loc, frame);
    if (child.name == "param") {
      module.params.push_back(Param{valueOf(*settings, "name"), valueOf(*settings, "value"), at});
      continue;
    }
    InputConfig input;
    input.port = valueOf(*settings, "port");
    input.loc = at;
    if (const std::string text = valueOf(*settings, "initial-messages"); !text.empty()) {
      const std::optional<long long> count = parseInteger(text);
      if (!count || *count < -2147483647LL || *count > 2147483647LL) {
        error(at.attribute("initial-messages"),
              mustBe(child, "initial-messages", "an integer", text));
      } else {
        input.initialMessages = static_cast<int>(*count);
      }
    }
    if (settings->count("mode") != 0) {
      const std::string text = valueOf(*settings, "mode");
      if (const std::optional<InputMode> mode = parseInputMode(text)) {
        input.mode = *mode;
      } else {
        error(at.attribute("mode"), mustBe(child, "mode", "one of fifo, latest", text));
      }
    }
    module.inputs.push_back(std::move(input));
  }
  level.nodes.insert(id);
  own.modules.push_back(std::move(module));
}

void Expander::addFilter(const TemplateElement& element, Frame& frame, Level& level,
                         Fragment& own) {
  const std::optional<Values> values = substitute(element, frame);
  if (!values || !required(element, *values, frame, {"id", "type"})) return;
  Filter filter;
  const std::string id = valueOf(*values, "id");
  filter.loc = located(element.loc, frame);
  if (!isPlainId(id)) {
    error(filter.loc.attribute("id"), "id '" + id + "' must not contain '.' or '" +
                                          std::string(1, kInstanceSeparator) +
                                          "' (inside a composite, ids get the instance's prefix)");
    return;
  }
  filter.id = frame.prefix + id;
  filter.type = valueOf(*values, "type");
  filter.host = valueOf(*values, "host");
  if (filter.host.empty()) filter.host = frame.host;
  for (const TemplateElement& child : element.children) {
    if (const std::optional<Values> settings = substitute(child, frame)) {
      filter.params.push_back(Param{valueOf(*settings, "name"), valueOf(*settings, "value"),
                                    located(child.loc, frame)});
    }
  }
  level.nodes.insert(id);
  own.filters.push_back(std::move(filter));
}

void Expander::addInstance(const TemplateElement& element, Frame& frame, Level& level,
                           Fragment& nested) {
  const std::optional<Values> values = substitute(element, frame);
  if (!values || !required(element, *values, frame, {"id", "composite"})) return;
  const std::string id = valueOf(*values, "id");
  const SourceLocation at = located(element.loc, frame);
  if (!checkInstanceId(id, at, level)) return;
  std::vector<Param> args;
  for (const TemplateElement& child : element.children) {
    if (const std::optional<Values> settings = substitute(child, frame)) {
      args.push_back(Param{valueOf(*settings, "name"), valueOf(*settings, "value"),
                           located(child.loc, frame)});
    }
  }
  std::string host = valueOf(*values, "host");
  if (host.empty()) host = frame.host;
  level.instances[id] =
      expandInstance(id, valueOf(*values, "composite"), host, args, at, &frame, nested);
}

void Expander::addConnection(const TemplateElement& element, Frame& frame, const Level& level,
                             Fragment& own) {
  const std::optional<Values> values = substitute(element, frame);
  if (!values || !required(element, *values, frame, {"from", "to"})) return;
  Connection connection;
  connection.loc = located(element.loc, frame);
  std::optional<Endpoint> ends[2];
  const char* names[2] = {"from", "to"};
  for (int i = 0; i < 2; ++i) {
    const std::string text = valueOf(*values, names[i]);
    const std::optional<Endpoint> endpoint = parseEndpoint(text);
    if (!endpoint) {
      error(connection.loc.attribute(names[i]),
            "endpoint '" + text + "' must be written node.port");
      continue;
    }
    ends[i] = resolve(level, *endpoint, i == 0, connection.loc.attribute(names[i]));
  }
  if (const std::string text = valueOf(*values, "capacity"); !text.empty()) {
    const std::optional<long long> capacity = parseInteger(text);
    if (!capacity || *capacity < -2147483647LL || *capacity > 2147483647LL) {
      error(connection.loc.attribute("capacity"), mustBe(element, "capacity", "an integer", text));
    } else {
      connection.capacity = static_cast<int>(*capacity);
    }
  }
  if (values->count("policy") != 0) {
    const std::string text = valueOf(*values, "policy");
    if (const std::optional<QueuePolicy> policy = parseQueuePolicy(text)) {
      connection.policy = *policy;
    } else {
      error(connection.loc.attribute("policy"),
            mustBe(element, "policy", "one of block, drop-oldest, drop-newest", text));
    }
  }
  if (!ends[0] || !ends[1]) return;
  connection.from = *ends[0];
  connection.to = *ends[1];
  own.connections.push_back(std::move(connection));
}

std::optional<Endpoint> Expander::resolve(const Level& level, const Endpoint& endpoint, bool source,
                                          const SourceLocation& at) {
  if (const auto it = level.instances.find(endpoint.node); it != level.instances.end()) {
    const InstancePorts& ports = it->second;
    if (ports.failed) return std::nullopt;
    const auto& wanted = source ? ports.outputs : ports.inputs;
    const auto& other = source ? ports.inputs : ports.outputs;
    const std::string instance =
        "instance '" + endpoint.node + "' (composite '" + ports.composite + "')";
    if (const auto port = wanted.find(endpoint.port); port != wanted.end()) return port->second;
    if (other.count(endpoint.port) != 0) {
      error(at, "'" + toString(endpoint) + "' is an " + (source ? "input" : "output") + " of " +
                    instance + "; a connection goes from an output to an input");
      return std::nullopt;
    }
    const std::vector<std::string> names = portNames(wanted);
    error(at, instance + " has no " + (source ? "output" : "input") + " '" + endpoint.port + "' (" +
                  (source ? "outputs: " : "inputs: ") + joinNames(names) + ")" +
                  didYouMean(endpoint.port, names));
    return std::nullopt;
  }
  if (level.nodes.count(endpoint.node) != 0) {
    return Endpoint{level.prefix + endpoint.node, endpoint.port};
  }
  if (level.composite.empty()) return endpoint;  // validate() reports unknown nodes
  std::vector<std::string> known(level.nodes.begin(), level.nodes.end());
  for (const auto& entry : level.instances) known.push_back(entry.first);
  error(at, "no module, filter or instance '" + endpoint.node + "' in composite '" +
                level.composite + "' (known: " + joinNames(known) + ")" +
                didYouMean(endpoint.node, known));
  return std::nullopt;
}

std::optional<Endpoint> Expander::portEndpoint(const CompositePort& port, bool source, Frame& frame,
                                               const Level& level) {
  const char* attribute = source ? "from" : "to";
  const SourceLocation at = located(port.loc, frame).attribute(attribute);
  if (port.endpoint.empty()) return std::nullopt;  // reported when loading
  Result<std::string> text = substituteTemplate(port.endpoint, frame.scope);
  if (!text) {
    error(at, "port '" + port.name + "': " + text.error().message);
    return std::nullopt;
  }
  const std::optional<Endpoint> endpoint = parseEndpoint(*text);
  if (!endpoint) {
    error(at, "endpoint '" + *text + "' must be written node.port");
    return std::nullopt;
  }
  return resolve(level, *endpoint, source, at);
}

InstancePorts Expander::expandBody(Frame& frame, Fragment& out) {
  const Composite& composite = *frame.composite;
  Level level;
  level.prefix = frame.prefix;
  level.composite = composite.name;
  Fragment own;
  Fragment nested;
  walk(composite.modules, frame,
       [&](const TemplateElement& element) { addModule(element, frame, level, own); });
  walk(composite.filters, frame,
       [&](const TemplateElement& element) { addFilter(element, frame, level, own); });
  walk(composite.instances, frame,
       [&](const TemplateElement& element) { addInstance(element, frame, level, nested); });
  walk(composite.connections, frame,
       [&](const TemplateElement& element) { addConnection(element, frame, level, own); });
  InstancePorts ports;
  ports.composite = composite.name;
  for (const CompositePort& port : composite.inputs) {
    ports.inputs[port.name] = portEndpoint(port, false, frame, level);
  }
  for (const CompositePort& port : composite.outputs) {
    ports.outputs[port.name] = portEndpoint(port, true, frame, level);
  }
  out.append(std::move(own));
  out.append(std::move(nested));
  return ports;
}

}  // namespace vrflow::app::detail
