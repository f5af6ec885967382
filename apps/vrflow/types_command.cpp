#include "types_command.hpp"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>

#include "vrflow/app/closest_name.hpp"
#include "vrflow/base/version.hpp"
#include "vrflow/daemon/filter_registry.hpp"
#include "vrflow/run/prepare.hpp"
#include "vrflow/run/runner.hpp"

namespace vrflow::apps {
namespace {

using nlohmann::ordered_json;

// Every module has these two ports (app::kBeginItPort, app::kEndItPort): not listed per type.
bool implicitPort(const app::PortSpec& port) {
  return port.name == app::kBeginItPort || port.name == app::kEndItPort;
}

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

// The first line of a type's documentation, cut to `width` characters.
std::string summary(const std::string& doc, std::size_t width) {
  std::string line = doc.substr(0, doc.find('\n'));
  if (line.size() > width) line = line.substr(0, width - 3) + "...";
  return line;
}

// `text` without the spaces at its end (a column left empty).
std::string trimmed(std::string text) {
  text.erase(text.find_last_not_of(' ') + 1);
  return text;
}

ordered_json portsJson(const std::vector<app::PortSpec>& ports) {
  ordered_json array = ordered_json::array();
  for (const auto& p : ports) {
    if (implicitPort(p)) continue;
    array.push_back({{"name", p.name},
                     {"direction", p.isInput ? "input" : "output"},
                     {"data", p.data},
                     {"stamps_only", p.stampsOnly},
                     {"required", p.required},
                     {"doc", p.doc}});
  }
  return array;
}

ordered_json paramsJson(const std::vector<app::ParamSpec>& params) {
  ordered_json array = ordered_json::array();
  for (const auto& p : params) {
    ordered_json j;
    j["name"] = p.name;
    j["type"] = app::toString(p.type);
    j["default"] = p.defaultValue;
    j["min"] = p.min ? ordered_json(*p.min) : ordered_json(nullptr);
    j["max"] = p.max ? ordered_json(*p.max) : ordered_json(nullptr);
    j["choices"] = p.choices;
    j["access"] = app::toString(p.access);
    j["doc"] = p.doc;
    array.push_back(j);
  }
  return array;
}

ordered_json moduleJson(const app::ModuleType& type) {
  ordered_json j;
  j["package"] = type.package;
  j["type"] = type.type;
  j["kind"] = app::toString(type.kind);
  j["doc"] = type.doc;
  j["executable"] = type.executable;
  j["manifest"] = type.loc.file;
  j["ports"] = portsJson(type.ports);
  j["parameters"] = paramsJson(type.params);
  return j;
}

ordered_json filterJson(const app::FilterType& type, bool plugin) {
  ordered_json j;
  j["name"] = type.name;
  j["origin"] = plugin ? "plugin" : "built-in";
  j["doc"] = type.doc;
  j["ports"] = portsJson(type.portsFor({}));  // with the parameters' defaults
  j["parameters"] = paramsJson(type.params);
  j["initial_messages"] = type.initialMessagesFor({});
  return j;
}

// The text of one type in detail: what `ports` and `parameters` of its JSON say, as columns.
void printPorts(const std::vector<app::PortSpec>& ports, const char* note) {
  for (const bool inputs : {true, false}) {
    std::string lines;
    for (const auto& p : ports) {
      if (p.isInput != inputs || implicitPort(p)) continue;
      std::string flags = p.required ? "required" : "";
      if (p.stampsOnly) flags += flags.empty() ? "stamps only" : ", stamps only";
      char line[256];
      std::snprintf(line, sizeof line, "    %-16s %-14s %-10s ", p.name.c_str(), p.data.c_str(),
                    flags.c_str());
      lines += trimmed(line + p.doc) + "\n";
    }
    if (lines.empty()) continue;
    std::printf("  %s%s:\n%s", inputs ? "inputs" : "outputs", note, lines.c_str());
  }
}

void printParams(const std::vector<app::ParamSpec>& params) {
  if (params.empty()) return;
  std::printf("  parameters:\n");
  for (const auto& p : params) {
    std::string range;
    if (!p.choices.empty()) {
      for (const auto& c : p.choices) range += (range.empty() ? "" : "|") + c;
    } else if (p.min || p.max) {
      range = "[" + (p.min ? number(*p.min) : std::string("-inf")) + ", " +
              (p.max ? number(*p.max) : std::string("inf")) + "]";
    }
    const std::string value = p.defaultValue.empty() ? "(none)" : p.defaultValue;
    char line[512];
    std::snprintf(line, sizeof line, "    %-16s %-7s default %-10s %-16s ", p.name.c_str(),
                  app::toString(p.type).c_str(), value.c_str(), range.c_str());
    std::printf("%s\n", trimmed(line + p.doc).c_str());
  }
}

void printModule(const app::ModuleType& type) {
  std::printf("%s/%s (module, %s)\n", type.package.c_str(), type.type.c_str(),
              app::toString(type.kind).c_str());
  if (!type.doc.empty()) std::printf("  %s\n", type.doc.c_str());
  std::printf("  executable: %s\n  manifest: %s:%d\n", type.executable.c_str(),
              type.loc.file.c_str(), type.loc.line);
  printPorts(type.ports, "");
  printParams(type.params);
}

void printFilter(const app::FilterType& type, bool plugin) {
  std::printf("%s (filter, %s)\n", type.name.c_str(), plugin ? "plugin" : "built-in");
  if (!type.doc.empty()) std::printf("  %s\n", type.doc.c_str());
  printPorts(type.portsFor({}), " (with the default parameters)");
  printParams(type.params);
  if (const int initial = type.initialMessagesFor({}); initial > 0) {
    std::printf("  emits %d message(s) at start-up\n", initial);
  }
}

}  // namespace

CLI::App* addTypesCommand(CLI::App& cli, TypesOptions& into) {
  auto* command = cli.add_subcommand(
      "types",
      "List the module types of the node packages and the filter types, with their "
      "ports and parameters");
  command->add_option("NAME", into.name,
                      "A package, PACKAGE/TYPE or a filter type: show it in detail");
  command->add_flag("--json", into.json, "Print JSON (every detail of every type shown)");
  command->add_option("--packages", into.packageDirs, "Extra folder of node packages (repeatable)")
      ->allow_extra_args(false);
  return command;
}

int runTypes(const TypesOptions& options) {
  // The filter types of the process before any plugin is loaded are the built-in ones.
  std::set<std::string> builtIn;
  const app::Catalog builtInCatalog = daemon::makeCatalog();  // alive while its types are read
  for (const auto* f : builtInCatalog.filterTypes()) builtIn.insert(f->name);
  auto loaded = run::loadCatalog(options.packageDirs);
  if (!loaded) {
    std::fprintf(stderr, "vrflow: %s\n", loaded.error().message.c_str());
    return run::kExitInvalid;
  }
  const app::Catalog& catalog = *loaded;
  const auto isPlugin = [&](const app::FilterType& f) { return builtIn.count(f.name) == 0; };

  std::vector<const app::ModuleType*> modules;
  std::vector<const app::FilterType*> filters;
  if (options.name.empty()) {
    modules = catalog.moduleTypes();
    filters = catalog.filterTypes();
  } else if (const auto slash = options.name.find('/'); slash != std::string::npos) {
    const auto* type =
        catalog.findModule(options.name.substr(0, slash), options.name.substr(slash + 1));
    if (type != nullptr) modules.push_back(type);
  } else {
    modules = catalog.moduleTypesIn(options.name);
    if (const auto* filter = catalog.findFilter(options.name)) filters.push_back(filter);
  }
  if (!options.name.empty() && modules.empty() && filters.empty()) {
    std::vector<std::string> names = catalog.packages();
    for (const auto* m : catalog.moduleTypes()) names.push_back(m->package + "/" + m->type);
    for (const auto* f : catalog.filterTypes()) names.push_back(f->name);
    const auto close = app::closestName(options.name, names);
    std::fprintf(stderr,
                 "vrflow: no package, module type or filter type '%s'%s (`vrflow types` lists "
                 "them; packages are searched in --packages, $VRFLOW_PACKAGE_PATH and the "
                 "installed ones)\n",
                 options.name.c_str(), close ? ("; did you mean '" + *close + "'?").c_str() : "");
    return run::kExitInvalid;
  }

  if (options.json) {
    ordered_json j;
    j["vrflow_version"] = versionText();
    j["modules"] = ordered_json::array();
    for (const auto* m : modules) j["modules"].push_back(moduleJson(*m));
    j["filters"] = ordered_json::array();
    for (const auto* f : filters) j["filters"].push_back(filterJson(*f, isPlugin(*f)));
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  if (!options.name.empty()) {
    bool first = true;
    for (const auto* m : modules) {
      std::printf("%s", first ? "" : "\n");
      printModule(*m);
      first = false;
    }
    for (const auto* f : filters) {
      std::printf("%s", first ? "" : "\n");
      printFilter(*f, isPlugin(*f));
      first = false;
    }
    return 0;
  }
  std::printf(
      "Module types (`vrflow types PACKAGE` or PACKAGE/TYPE shows ports and parameters):\n");
  for (const auto* m : modules) {
    const std::string name = m->package + "/" + m->type;
    std::printf("  %-30s %-10s %s\n", name.c_str(), app::toString(m->kind).c_str(),
                summary(m->doc, 70).c_str());
  }
  std::printf("Filter types (`vrflow types FILTER` shows ports and parameters):\n");
  for (const auto* f : filters) {
    std::printf("  %-30s %-10s %s\n", f->name.c_str(), isPlugin(*f) ? "plugin" : "built-in",
                summary(f->doc, 70).c_str());
  }
  return 0;
}

}  // namespace vrflow::apps
