#include "vrflow/app/validate.hpp"

#include <cstdio>

#include "application_reader.hpp"
#include "element_reader.hpp"
#include "file_io.hpp"
#include "text_util.hpp"
#include "validation.hpp"
#include "vrflow/app/expand.hpp"

namespace vrflow::app {
namespace detail {
namespace {

std::string moduleLabel(const Module& module) {
  return "module '" + module.id + "' (" + module.package + "/" + module.type + ")";
}

std::string filterLabel(const Filter& filter) {
  return "filter '" + filter.id + "' (" + filter.type + ")";
}

void requireNonEmpty(Validation& v, const std::string& value, const SourceLocation& loc,
                     std::string_view element, std::string_view attribute) {
  if (value.empty()) v.error(loc, missingAttributeMessage(element, attribute));
}

// Ids are printed in reports, logs and messages, one per line: no control characters.
void checkPrintableId(Validation& v, const std::string& id, const SourceLocation& loc) {
  if (const std::optional<char> c = firstControlCharacter(id)) {
    char code[8];
    std::snprintf(code, sizeof code, "U+%04X",
                  static_cast<unsigned>(static_cast<unsigned char>(*c)));
    v.error(loc.attribute("id"), "id '" + escapeControlCharacters(id) +
                                     "' contains a control character (" + code +
                                     "); ids are printed one per line in reports and logs");
  }
}

// Ids of modules and filters share one namespace (connections name them); hosts have theirs.
void checkIds(Validation& v) {
  std::map<std::string, const SourceLocation*, std::less<>> hosts;
  for (const Host& host : v.app.hosts) {
    if (const auto problem = hostAddressProblem(host.address)) {
      v.error(host.loc.attribute("address"), "address '" + escapeControlCharacters(host.address) +
                                                 "' of host '" + escapeControlCharacters(host.id) +
                                                 "' " + *problem);
    }
    requireNonEmpty(v, host.id, host.loc, "host", "id");
    if (host.id.empty()) continue;
    checkPrintableId(v, host.id, host.loc);
    const auto [it, added] = hosts.emplace(host.id, &host.loc);
    if (!added) {
      v.error(host.loc.attribute("id"),
              "duplicate host id '" + host.id + "' (first defined" + atLine(*it->second) + ")");
    }
  }
  std::map<std::string, std::pair<const SourceLocation*, const char*>, std::less<>> nodes;
  const auto checkNodeId = [&](const std::string& id, const SourceLocation& loc,
                               const char* element) {
    requireNonEmpty(v, id, loc, element, "id");
    if (id.empty()) return;
    checkPrintableId(v, id, loc);
    if (id.find('.') != std::string::npos) {
      v.error(loc.attribute("id"),
              "id '" + id + "' must not contain '.' (connections write node.port)");
    }
    const auto [it, added] = nodes.emplace(id, std::make_pair(&loc, element));
    if (!added) {
      v.error(loc.attribute("id"), "duplicate id '" + id + "' (already used by the " +
                                       it->second.second + atLine(*it->second.first) + ")");
    }
  };
  for (const Module& module : v.app.modules) checkNodeId(module.id, module.loc, "module");
  for (const Filter& filter : v.app.filters) checkNodeId(filter.id, filter.loc, "filter");
}

void checkHost(Validation& v, const std::string& host, const SourceLocation& loc) {
  if (host.empty() || findHost(v.app, host) != nullptr) return;
  std::vector<std::string> ids;
  for (const Host& known : v.app.hosts) ids.push_back(known.id);
  v.error(loc.attribute("host"),
          "unknown host '" + host + "' (hosts: " + joinNames(ids) + ")" + didYouMean(host, ids));
}

void checkModuleType(Validation& v, const Module& module) {
  requireNonEmpty(v, module.package, module.loc, "module", "package");
  requireNonEmpty(v, module.type, module.loc, "module", "type");
  if (module.package.empty() || module.type.empty()) return;
  if (!v.catalog.hasPackage(module.package)) {
    const std::vector<std::string> packages = v.catalog.packages();
    const std::string known = packages.empty()
                                  ? "no packages are loaded; check the package search path"
                                  : "packages: " + joinNames(packages);
    v.error(module.loc.attribute("package"), "unknown package '" + module.package + "' (" + known +
                                                 ")" + didYouMean(module.package, packages));
    return;
  }
  if (v.catalog.findModule(module.package, module.type) != nullptr) return;
  std::vector<std::string> types;
  for (const ModuleType* type : v.catalog.moduleTypesIn(module.package)) {
    types.push_back(type->type);
  }
  v.error(module.loc.attribute("type"),
          "unknown module type '" + module.package + "/" + module.type + "' (known in package " +
              module.package + ": " + joinNames(types) + ")" + didYouMean(module.type, types));
}

void checkFilterType(Validation& v, const Filter& filter) {
  requireNonEmpty(v, filter.type, filter.loc, "filter", "type");
  if (filter.type.empty() || v.catalog.findFilter(filter.type) != nullptr) return;
  std::vector<std::string> names;
  for (const FilterType* type : v.catalog.filterTypes()) names.push_back(type->name);
  v.error(filter.loc.attribute("type"), "unknown filter type '" + filter.type +
                                            "' (known: " + joinNames(names) + ")" +
                                            didYouMean(filter.type, names));
}

void checkParams(Validation& v, const std::vector<Param>& params,
                 const std::vector<ParamSpec>& specs, const std::string& label) {
  std::vector<std::string> declared;
  for (const ParamSpec& spec : specs) declared.push_back(spec.name);
  for (std::size_t i = 0; i < params.size(); ++i) {
    const Param& param = params[i];
    requireNonEmpty(v, param.name, param.loc, "param", "name");
    if (param.name.empty()) continue;
    const Param* first = findParam(params, param.name);
    if (first != &param) {
      v.error(param.loc.attribute("name"), "parameter '" + param.name + "' is set twice on " +
                                               label + " (first" + atLine(first->loc) + ")");
      continue;
    }
    const auto spec = std::find_if(specs.begin(), specs.end(),
                                   [&](const ParamSpec& s) { return s.name == param.name; });
    if (spec == specs.end()) {
      v.error(param.loc.attribute("name"), label + " has no parameter '" + param.name +
                                               "' (parameters: " + joinNames(declared) + ")" +
                                               didYouMean(param.name, declared));
      continue;
    }
    if (const auto problem = checkParamValue(*spec, param.value)) {
      v.error(param.loc.attribute("value"),
              "parameter '" + param.name + "' of " + label + " " + *problem);
    }
  }
}

void checkEditor(Validation& v) {
  std::map<std::string, const SourceLocation*, std::less<>> seen;
  for (const EditorNode& node : v.app.editor) {
    requireNonEmpty(v, node.ref, node.loc, "node", "ref");
    if (node.ref.empty()) continue;
    if (v.find(node.ref) == nullptr) {
      v.warning(node.loc.attribute("ref"),
                "editor position for unknown module or filter '" + node.ref + "'");
    }
    const auto [it, added] = seen.emplace(node.ref, &node.loc);
    if (!added) {
      v.warning(node.loc.attribute("ref"),
                "second editor position for '" + node.ref + "' (first" + atLine(*it->second) + ")");
    }
  }
}

// True when every parameter is declared by the type and its value is valid.
bool paramsValid(const std::vector<Param>& params, const FilterType& type) {
  return std::all_of(params.begin(), params.end(), [&](const Param& param) {
    const auto spec = std::find_if(type.params.begin(), type.params.end(),
                                   [&](const ParamSpec& s) { return s.name == param.name; });
    return spec != type.params.end() && !checkParamValue(*spec, param.value);
  });
}

}  // namespace

Validation::Validation(const Application& application, const Catalog& types)
    : app(application), catalog(types) {
  for (const Module& module : app.modules) {
    if (module.id.empty() || byId_.count(module.id) != 0) continue;
    NodeInfo node;
    node.module = &module;
    node.moduleType = catalog.findModule(module.package, module.type);
    if (node.moduleType != nullptr) node.ports = node.moduleType->ports;
    node.portsKnown = node.moduleType != nullptr;
    node.label = moduleLabel(module);
    byId_.emplace(module.id, nodes.size());
    nodes.push_back(std::move(node));
  }
  for (const Filter& filter : app.filters) {
    if (filter.id.empty() || byId_.count(filter.id) != 0) continue;
    NodeInfo node;
    node.filter = &filter;
    node.filterType = catalog.findFilter(filter.type);
    // Ports are made from the parameters only when they are valid: an out-of-range `inputs`
    // is reported as such, not as hundreds of unconnected inputs.
    node.portsKnown = node.filterType != nullptr && paramsValid(filter.params, *node.filterType);
    if (node.portsKnown) node.ports = node.filterType->portsFor(filter.params);
    node.label = filterLabel(filter);
    byId_.emplace(filter.id, nodes.size());
    nodes.push_back(std::move(node));
  }
  for (const NodeInfo& node : nodes) ids_.push_back(node.id());
}

const NodeInfo* Validation::find(std::string_view id) const {
  const auto it = byId_.find(id);
  return it == byId_.end() ? nullptr : &nodes[it->second];
}

std::size_t Validation::indexOf(std::string_view id) const {
  const auto it = byId_.find(id);
  return it == byId_.end() ? nodes.size() : it->second;
}

void Validation::error(const SourceLocation& loc, std::string message) {
  Diagnostic diagnostic{loc, Diagnostic::Error, std::move(message)};
  diagnostic.loc.attributes.clear();
  diagnostics.push_back(std::move(diagnostic));
}

void Validation::warning(const SourceLocation& loc, std::string message) {
  Diagnostic diagnostic{loc, Diagnostic::Warning, std::move(message)};
  diagnostic.loc.attributes.clear();
  diagnostics.push_back(std::move(diagnostic));
}

std::string atLine(const SourceLocation& loc) {
  return loc.line > 0 ? " at line " + std::to_string(loc.line) : std::string();
}

void checkNodes(Validation& v) {
  checkIds(v);
  for (const Module& module : v.app.modules) {
    checkHost(v, module.host, module.loc);
    checkModuleType(v, module);
    if (const ModuleType* type = v.catalog.findModule(module.package, module.type)) {
      checkParams(v, module.params, type->params, moduleLabel(module));
    }
  }
  for (const Filter& filter : v.app.filters) {
    checkHost(v, filter.host, filter.loc);
    checkFilterType(v, filter);
    if (const FilterType* type = v.catalog.findFilter(filter.type)) {
      checkParams(v, filter.params, type->params, filterLabel(filter));
      if (type->check) {
        if (const auto problem = type->check(filter.params)) {
          v.error(filter.loc, filterLabel(filter) + ": " + *problem);
        }
      }
    }
  }
  checkEditor(v);
}

}  // namespace detail

std::vector<Diagnostic> validate(const Application& app, const Catalog& catalog) {
  if (!app.instances.empty()) {
    return validateWithComposites(app, catalog, defaultCompositeSources(app));
  }
  try {
    detail::Validation validation(app, catalog);
    detail::checkNodes(validation);
    detail::checkConnections(validation);
    detail::checkCycles(validation);
    detail::checkMpiJobs(validation);
    sortAndDeduplicate(validation.diagnostics);
    return std::move(validation.diagnostics);
  } catch (const std::exception& e) {
    return {Diagnostic{SourceLocation{app.file, 0, 0}, Diagnostic::Error,
                       std::string("validation failed: ") + e.what()}};
  }
}

std::vector<Diagnostic> checkApplicationString(std::string_view xml, const std::string& fileName,
                                               const Catalog& catalog) {
  std::vector<Diagnostic> problems;
  try {
    const std::optional<Application> app = detail::readApplication(xml, fileName, problems);
    if (app) {
      std::vector<Diagnostic> found = validate(*app, catalog);
      problems.insert(problems.end(), found.begin(), found.end());
    }
  } catch (const std::exception& e) {
    problems.push_back(Diagnostic{SourceLocation{fileName, 0, 0}, Diagnostic::Error,
                                  std::string("cannot check application (") + e.what() + ")"});
  }
  sortAndDeduplicate(problems);
  return problems;
}

std::vector<Diagnostic> checkApplicationFile(const std::string& path, const Catalog& catalog) {
  Result<std::string> content = detail::readWholeFile(path);
  if (!content) {
    return {Diagnostic{SourceLocation{path, 0, 0}, Diagnostic::Error, content.error().message}};
  }
  return checkApplicationString(*content, path, catalog);
}

}  // namespace vrflow::app
