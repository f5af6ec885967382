#include "vrflow/app/expand.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>

#include "composite_reader.hpp"
#include "expansion.hpp"
#include "file_io.hpp"
#include "text_util.hpp"
#include "validation.hpp"
#include "vrflow/app/validate.hpp"
#include "vrflow/base/executable_dir.hpp"

namespace vrflow::app {
namespace detail {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> paramNames(const Composite& composite) {
  std::vector<std::string> names;
  for (const CompositeParam& param : composite.params) names.push_back(param.name);
  return names;
}

std::string instanceLabel(const std::string& id, const std::string& composite) {
  return "instance '" + id + "' of composite '" + composite + "'";
}

// "an integer >= 2", "an integer in [0, 9]", for messages.
std::string rangeText(const CompositeParam& param) {
  if (param.min && param.max) {
    return "an integer in [" + std::to_string(*param.min) + ", " + std::to_string(*param.max) + "]";
  }
  if (param.min) return "an integer >= " + std::to_string(*param.min);
  return "an integer <= " + std::to_string(*param.max);
}

}  // namespace

void Fragment::append(Fragment&& other) {
  std::move(other.modules.begin(), other.modules.end(), std::back_inserter(modules));
  std::move(other.filters.begin(), other.filters.end(), std::back_inserter(filters));
  std::move(other.connections.begin(), other.connections.end(), std::back_inserter(connections));
}

SourceLocation located(const SourceLocation& loc, const Frame& frame) {
  SourceLocation copy = loc;
  copy.expandedFrom = frame.sites;
  return copy;
}

bool isPlainId(const std::string& id) {
  return id.find('.') == std::string::npos && id.find(kInstanceSeparator) == std::string::npos;
}

Expander::Expander(const Application& app, const CompositeSources& sources,
                   std::vector<Diagnostic>& problems)
    : app_(app), sources_(sources), problems_(problems) {}

void Expander::error(const SourceLocation& at, std::string message) {
  // A problem in a <repeat> comes back at every iteration: keep one, so that memory stays
  // bounded by the distinct problems (sortAndDeduplicate() would keep the first one too).
  std::string key =
      at.file + ":" + std::to_string(at.line) + ":" + std::to_string(at.column) + ":" + message;
  if (!reported_.insert(std::move(key)).second) return;
  Diagnostic diagnostic{at, Diagnostic::Error, std::move(message)};
  diagnostic.loc.attributes.clear();
  problems_.push_back(std::move(diagnostic));
}

const Composite* Expander::loadFromSearchPath(const std::string& name) {
  const auto cached = loaded_.find(name);
  if (cached != loaded_.end()) return cached->second.get();
  std::unique_ptr<Composite>& slot = loaded_[name];
  const bool fileName = std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-';
  });
  if (!fileName || name.empty() || name.front() == '-') return nullptr;
  for (const std::string& dir : sources_.searchPath) {
    const std::string path =
        (fs::path(dir) / (name + std::string(kCompositeFileSuffix))).lexically_normal().string();
    std::error_code ec;
    if (!fs::exists(path, ec)) continue;
    badFiles_.insert(name);  // until it loads
    Result<std::string> text = readWholeFile(path);
    if (!text) {
      error(SourceLocation{path, 0, 0}, text.error().message);
      return nullptr;
    }
    std::optional<Composite> composite = readCompositeFile(*text, path, problems_);
    if (!composite) return nullptr;
    if (composite->name != name) {
      if (composite->name.empty()) return nullptr;  // no usable root: reported while reading
      error(composite->loc.attribute("name"),
            "this file defines composite '" + composite->name + "', but composite '" + name +
                "' is looked up in it (a composite's file is named NAME" +
                std::string(kCompositeFileSuffix) + ")");
      return nullptr;
    }
    badFiles_.erase(name);
    slot = std::make_unique<Composite>(std::move(*composite));
    return slot.get();
  }
  return nullptr;
}

const Composite* Expander::lookup(const std::string& name, const SourceLocation& at) {
  if (const Composite* own = findComposite(app_, name)) return own;
  for (const Composite& given : sources_.composites) {
    if (given.name == name) return &given;
  }
  if (const Composite* found = loadFromSearchPath(name)) return found;
  if (badFiles_.count(name) != 0) return nullptr;  // the problem is reported in its file
  const std::vector<std::string>& known = knownComposites();
  std::string searched = sources_.searchPath.empty()
                             ? "no search path"
                             : "searched for " + name + std::string(kCompositeFileSuffix) +
                                   " in: " + joinNames(sources_.searchPath);
  error(at, "unknown composite '" + name + "' (known: " + joinNames(known) + "; " + searched + ")" +
                didYouMean(name, known));
  return nullptr;
}

const std::vector<std::string>& Expander::knownComposites() {
  if (known_) return *known_;
  std::vector<std::string> known;
  for (const Composite& own : app_.composites) known.push_back(own.name);
  for (const Composite& given : sources_.composites) known.push_back(given.name);
  const std::string suffix(kCompositeFileSuffix);
  for (const std::string& dir : sources_.searchPath) {
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string file = it->path().filename().string();
      if (file.size() > suffix.size() && file.ends_with(suffix)) {
        known.push_back(file.substr(0, file.size() - suffix.size()));
      }
    }
  }
  std::sort(known.begin(), known.end());
  known.erase(std::unique(known.begin(), known.end()), known.end());
  known_ = std::move(known);
  return *known_;
}

bool Expander::checkInstanceId(const std::string& id, const SourceLocation& at,
                               const Level& level) {
  if (id.empty()) return false;  // reported when loading
  if (!isPlainId(id)) {
    error(at.attribute("id"), "instance id '" + id + "' must not contain '.' or '" +
                                  std::string(1, kInstanceSeparator) +
                                  "' (ids inside it are written " + id +
                                  std::string(1, kInstanceSeparator) + "ID)");
    return false;
  }
  if (level.nodes.count(id) != 0 || level.instances.count(id) != 0) {
    error(at.attribute("id"), "duplicate id '" + id +
                                  "' (instances share ids with modules and "
                                  "filters)");
    return false;
  }
  return true;
}

bool Expander::bindParams(const Composite& composite, const std::vector<Param>& args,
                          const std::string& instance, const SourceLocation& at,
                          TemplateScope& scope) {
  const std::string label = instanceLabel(instance, composite.name);
  for (const Param& arg : args) {
    if (arg.name.empty()) continue;  // reported when loading
    if (findCompositeParam(composite, arg.name) == nullptr) {
      const std::vector<std::string> names = paramNames(composite);
      error(arg.loc.attribute("name"), "composite '" + composite.name + "' has no parameter '" +
                                           arg.name + "' (parameters: " + joinNames(names) + ")" +
                                           didYouMean(arg.name, names));
    } else if (const Param* first = findParam(args, arg.name); first != &arg) {
      error(arg.loc.attribute("name"), "parameter '" + arg.name + "' is set twice on " + label +
                                           " (first" + atLine(first->loc) + ")");
    }
  }
  bool bound = true;
  for (const CompositeParam& param : composite.params) {
    const Param* arg = findParam(args, param.name);
    if (arg == nullptr && !param.defaultValue) {
      error(at, label + " must set parameter '" + param.name + "' (it has no default)");
      bound = false;
      continue;
    }
    const std::string value = arg != nullptr ? arg->value : *param.defaultValue;
    if (param.min || param.max) {
      const std::optional<long long> number = parseInteger(value);
      if (!number || (param.min && *number < *param.min) || (param.max && *number > *param.max)) {
        error(arg != nullptr ? arg->loc.attribute("value") : at,
              "parameter '" + param.name + "' of " + label + " must be " + rangeText(param) +
                  ", got '" + value + "'");
        bound = false;
        continue;
      }
    }
    scope[param.name] = value;
  }
  scope[std::string(kInstanceTemplateName)] = instance;
  return bound;
}

InstancePorts Expander::expandInstance(const std::string& id, const std::string& composite,
                                       const std::string& host, const std::vector<Param>& args,
                                       const SourceLocation& at, const Frame* parent,
                                       Fragment& out) {
  InstancePorts ports;
  ports.composite = composite;
  ports.failed = true;
  const Composite* definition = lookup(composite, at.attribute("composite"));
  if (definition == nullptr) return ports;
  Frame frame;
  frame.composite = definition;
  frame.prefix = (parent != nullptr ? parent->prefix : std::string()) + id + kInstanceSeparator;
  frame.host = host;
  if (parent != nullptr) frame.active = parent->active;
  const std::string fullId = frame.prefix.substr(0, frame.prefix.size() - 1);
  if (std::find(frame.active.begin(), frame.active.end(), composite) != frame.active.end()) {
    std::string chain;
    for (const std::string& name : frame.active) chain += name + " -> ";
    error(at.attribute("composite"),
          "composite '" + composite + "' contains itself: " + chain + composite);
    return ports;
  }
  if (frame.active.size() >= kMaxCompositeDepth) {
    error(at.attribute("composite"),
          "composites are nested more than " + std::to_string(kMaxCompositeDepth) + " deep here");
    return ports;
  }
  frame.active.push_back(composite);
  frame.sites.push_back(InstanceSite{fullId, composite, at.file, at.line, at.column});
  frame.sites.insert(frame.sites.end(), at.expandedFrom.begin(), at.expandedFrom.end());
  if (!bindParams(*definition, args, fullId, at, frame.scope)) return ports;
  return expandBody(frame, out);
}

Application Expander::run() {
  Application flat;
  flat.name = app_.name;
  flat.packages = app_.packages;
  flat.hosts = app_.hosts;
  flat.file = app_.file;
  flat.modules = app_.modules;
  flat.filters = app_.filters;
  Level level;
  for (const Module& module : app_.modules) level.nodes.insert(module.id);
  for (const Filter& filter : app_.filters) level.nodes.insert(filter.id);
  Fragment inner;
  for (const Instance& instance : app_.instances) {
    if (!checkInstanceId(instance.id, instance.loc, level)) continue;
    level.instances[instance.id] =
        expandInstance(instance.id, instance.composite, effectiveHost(app_, instance.host),
                       instance.params, instance.loc, nullptr, inner);
  }
  for (const Connection& connection : app_.connections) {
    const auto from = resolve(level, connection.from, true, connection.loc.attribute("from"));
    const auto to = resolve(level, connection.to, false, connection.loc.attribute("to"));
    if (!from || !to) continue;
    Connection resolved = connection;
    resolved.from = *from;
    resolved.to = *to;
    flat.connections.push_back(std::move(resolved));
  }
  flat.modules.insert(flat.modules.end(), std::make_move_iterator(inner.modules.begin()),
                      std::make_move_iterator(inner.modules.end()));
  flat.filters.insert(flat.filters.end(), std::make_move_iterator(inner.filters.begin()),
                      std::make_move_iterator(inner.filters.end()));
  flat.connections.insert(flat.connections.end(),
                          std::make_move_iterator(inner.connections.begin()),
                          std::make_move_iterator(inner.connections.end()));
  for (const EditorNode& node : app_.editor) {
    if (level.instances.count(node.ref) == 0) flat.editor.push_back(node);
  }
  return flat;
}

}  // namespace detail

CompositeSources defaultCompositeSources(const Application& app,
                                         const std::vector<std::string>& extraDirs) {
  CompositeSources sources;
  if (!app.file.empty()) {
    const std::string dir = std::filesystem::path(app.file).parent_path().string();
    sources.searchPath.push_back(dir.empty() ? "." : dir);
  }
  sources.searchPath.insert(sources.searchPath.end(), extraDirs.begin(), extraDirs.end());
  if (const char* env = std::getenv("VRFLOW_COMPOSITE_PATH")) {
    std::string_view rest = env;
    while (!rest.empty()) {
      const std::size_t colon = rest.find(':');
      const std::string_view dir = rest.substr(0, colon);
      if (!dir.empty()) sources.searchPath.emplace_back(dir);
      rest = colon == std::string_view::npos ? std::string_view() : rest.substr(colon + 1);
    }
  }
  // Composites that node packages ship (the fluid's fluid_blocks), beside their manifests:
  // <folder of this executable>/../share/vrflow/composites, in the build tree and installs alike.
  if (const auto bin = executableDir(); !bin.empty()) {
    sources.searchPath.push_back((bin.parent_path() / "share/vrflow/composites").string());
  }
  return sources;
}

Result<Application> expandComposites(const Application& app, const CompositeSources& sources,
                                     std::vector<Diagnostic>* problems) {
  try {
    std::vector<Diagnostic> found;
    Application flat = detail::Expander(app, sources, found).run();
    sortAndDeduplicate(found);
    if (problems != nullptr) {
      problems->insert(problems->end(), found.begin(), found.end());
    } else if (hasErrors(found)) {
      std::string message = formatDiagnostics(found);
      message.pop_back();  // the final newline
      return makeError(std::move(message));
    }
    return flat;
  } catch (const std::exception& e) {
    return makeError(app.file + ": error: cannot expand composites (" + e.what() + ")");
  }
}

std::vector<Diagnostic> validateWithComposites(const Application& app, const Catalog& catalog,
                                               const CompositeSources& sources) {
  std::vector<Diagnostic> problems;
  Result<Application> flat = expandComposites(app, sources, &problems);
  if (flat) {
    std::vector<Diagnostic> more = validate(*flat, catalog);
    problems.insert(problems.end(), more.begin(), more.end());
  } else {
    problems.push_back(
        Diagnostic{SourceLocation{app.file, 0, 0}, Diagnostic::Error, flat.error().message});
  }
  sortAndDeduplicate(problems);
  return problems;
}

}  // namespace vrflow::app
