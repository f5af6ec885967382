#include "manifest_reader.hpp"

#include <algorithm>
#include <filesystem>

#include "element_reader.hpp"
#include "source_text.hpp"
#include "text_util.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/base/executable_dir.hpp"

namespace vrflow::app::detail {
namespace {

PortSpec readPort(const ReadContext& context, const pugi::xml_node& node, bool isInput) {
  const ElementReader reader =
      isInput ? ElementReader(context, node, {"name", "data", "stamps-only", "required", "doc"})
              : ElementReader(context, node, {"name", "data", "stamps-only", "doc"});
  PortSpec port;
  port.isInput = isInput;
  port.name = reader.required("name");
  port.data = reader.text("data", kAnyData);
  if (port.data.empty()) reader.errorAt("data", "attribute 'data' must not be empty (use 'any')");
  port.stampsOnly = reader.boolean("stamps-only", false);
  port.required = isInput && reader.boolean("required", false);
  port.doc = reader.text("doc");
  if (port.name == kBeginItPort || port.name == kEndItPort) {
    reader.errorAt("name", "port name '" + port.name +
                               "' is reserved: every module has beginIt and endIt implicitly");
  }
  forEachChild(context, node, {}, [](const pugi::xml_node&) {});
  return port;
}

ParamSpec readParamSpec(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node,
                             {"name", "type", "default", "min", "max", "choices", "access", "doc"});
  ParamSpec param;
  param.name = reader.required("name");
  const std::string typeText = reader.required("type");
  if (const auto type = parseParamType(typeText)) {
    param.type = *type;
  } else if (!typeText.empty()) {
    reader.errorAt("type", "unknown parameter type '" + typeText +
                               "' (types: int, float, bool, string, enum, vec3, file)");
  }
  param.defaultValue = reader.text("default");
  param.min = reader.optionalNumber("min");
  param.max = reader.optionalNumber("max");
  param.doc = reader.text("doc");
  const bool numeric = param.type == ParamType::Int || param.type == ParamType::Float ||
                       param.type == ParamType::Vec3;
  for (const char* bound : {"min", "max"}) {
    if (reader.has(bound) && !numeric) {
      reader.errorAt(bound, "attribute '" + std::string(bound) +
                                "' applies only to int, float and vec3 parameters");
    }
  }
  if (param.min && param.max && *param.min > *param.max) {
    reader.errorAt("min",
                   "min " + formatNumber(*param.min) + " is above max " + formatNumber(*param.max));
  }
  if (reader.has("choices")) {
    if (param.type != ParamType::Enum) {
      reader.errorAt("choices", "attribute 'choices' applies only to enum parameters");
    }
    const std::string choices = reader.text("choices");
    std::size_t start = 0;
    while (start <= choices.size()) {
      std::size_t end = choices.find(',', start);
      if (end == std::string::npos) end = choices.size();
      std::string choice = choices.substr(start, end - start);
      while (!choice.empty() && choice.front() == ' ') choice.erase(choice.begin());
      while (!choice.empty() && choice.back() == ' ') choice.pop_back();
      if (choice.empty()) {
        reader.errorAt("choices", "attribute 'choices' has an empty choice");
      } else {
        param.choices.push_back(std::move(choice));
      }
      start = end + 1;
    }
  } else if (param.type == ParamType::Enum && !typeText.empty()) {
    context.error(reader.loc(), missingAttributeMessage("param", "choices") + " (enum)");
  }
  if (reader.has("access")) {
    if (param.type != ParamType::File) {
      reader.errorAt("access", "attribute 'access' applies only to file parameters");
    }
    param.access = reader.keyword("access", FileAccess::Unstated, parseFileAccess, "input, output");
  }
  if (reader.has("default") && !param.name.empty()) {
    if (const auto problem = checkParamValue(param, param.defaultValue)) {
      reader.errorAt("default", "default of parameter '" + param.name + "' " + *problem);
    }
  }
  forEachChild(context, node, {}, [](const pugi::xml_node&) {});
  return param;
}

// The `bin` folder of the layout a manifest sits in: <prefix>/share/vrflow/GROUP/NAME/ (an
// install, or the build tree, which has the same shape) gives <prefix>/bin; empty elsewhere.
std::filesystem::path layoutBinFolder(const std::filesystem::path& manifestFolder) {
  const std::filesystem::path vrflowFolder = manifestFolder.parent_path().parent_path();
  const std::filesystem::path shareFolder = vrflowFolder.parent_path();
  if (vrflowFolder.filename() != "vrflow" || shareFolder.filename() != "share") return {};
  return shareFolder.parent_path() / "bin";
}

// Where a manifest's executable is: a path with a '/' is taken from the manifest's folder,
// whether the file is there yet or not (a module not built yet must fail naming that path, not
// the text written); a bare name is looked up in the package's folder, then in the `bin` folder
// of its layout, then beside the running program. A bare name found nowhere stays as written,
// with the folders looked in, for checkModuleFiles() to report.
void resolveExecutable(ModuleType& type, const std::string& executable,
                       const std::string& manifestFile) {
  namespace fs = std::filesystem;
  type.executable = executable;
  if (executable.empty() || fs::path(executable).is_absolute()) return;
  std::error_code ec;
  const fs::path folder = fs::absolute(fs::path(manifestFile), ec).parent_path().lexically_normal();
  if (ec) return;
  if (executable.find('/') != std::string::npos) {
    type.executable = (folder / executable).lexically_normal().string();
    return;
  }
  std::vector<fs::path> folders{folder, layoutBinFolder(folder), executableDir()};
  for (const fs::path& candidate : folders) {
    if (candidate.empty()) continue;
    const std::string where = candidate.lexically_normal().string();
    if (std::find(type.executableSearched.begin(), type.executableSearched.end(), where) !=
        type.executableSearched.end()) {
      continue;
    }
    const fs::path file = candidate / executable;
    if (fs::is_regular_file(file, ec)) {
      type.executable = file.lexically_normal().string();
      type.executableSearched.clear();
      return;
    }
    type.executableSearched.push_back(where);
  }
}

// What starts a module of this type: a program (`executable`), or a script (`script`, resolved
// against the manifest's folder) run by its `interpreter` (default python3, looked up on PATH
// when the module starts; docs/python.md).
void readProgram(const ReadContext& context, const ElementReader& reader, ModuleType& type) {
  const bool hasScript = reader.has("script");
  if (!hasScript) {
    if (reader.has("interpreter")) {
      context.error(reader.loc(), "interpreter is set on '" + type.type +
                                      "', which has no script: set script=\"FILE.py\" or "
                                      "remove interpreter");
    }
    resolveExecutable(type, reader.required("executable"), context.source.file());
    return;
  }
  if (reader.has("executable")) {
    context.error(reader.loc(), "module type '" + type.type +
                                    "' sets both executable and script: keep one (a script "
                                    "runs with its interpreter)");
  }
  const std::string script = reader.required("script");
  const std::string interpreter = reader.text("interpreter", "python3");
  if (interpreter.empty()) {
    context.error(reader.loc(), "interpreter of '" + type.type + "' is empty");
  }
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path folder =
      fs::absolute(fs::path(context.source.file()), ec).parent_path().lexically_normal();
  type.script =
      fs::path(script).is_absolute() ? script : (folder / script).lexically_normal().string();
  type.executable = interpreter;
}

ModuleType readModuleType(const ReadContext& context, const pugi::xml_node& node,
                          const std::string& package) {
  const ElementReader reader(
      context, node,
      {"type", "executable", "script", "interpreter", "kind", "mpi-ranks", "mpi-job"});
  ModuleType type;
  type.package = package;
  type.type = reader.required("type");
  readProgram(context, reader, type);
  type.kind = reader.keyword("kind", ModuleKind::Other, parseModuleKind,
                             "animator, interactor, viewer, input, other");
  type.loc = reader.loc();
  type.loc.attributes.clear();
  bool first = true;
  forEachChild(context, node, {"doc", "input", "output", "param"},
               [&](const pugi::xml_node& child) {
                 const std::string_view name = child.name();
                 const bool wasFirst = first;
                 first = false;
                 if (name == "doc") {
                   const ElementReader docReader(context, child, {});
                   if (!wasFirst) {
                     context.error(docReader.loc(), "<doc> must be the first child of <module>");
                   }
                   type.doc = readTextElement(context, child);
                   return;
                 }
                 if (name == "param") {
                   const ParamSpec param = readParamSpec(context, child);
                   if (!param.name.empty() && type.findParam(param.name) != nullptr) {
                     context.error(
                         context.source.element(child).attribute("name"),
                         "parameter '" + param.name + "' is declared twice in '" + type.type + "'");
                   }
                   type.params.push_back(param);
                   return;
                 }
                 const PortSpec port = readPort(context, child, name == "input");
                 if (!port.name.empty() && type.findPort(port.name) != nullptr) {
                   context.error(context.source.element(child).attribute("name"),
                                 "port '" + port.name + "' is declared twice in '" + type.type +
                                     "' (inputs and outputs share one namespace)");
                 }
                 type.ports.push_back(port);
               });
  type.mpiRanksParam = reader.text("mpi-ranks");
  if (!type.mpiRanksParam.empty()) {
    const ParamSpec* param = type.findParam(type.mpiRanksParam);
    if (param == nullptr || param->type != ParamType::Int) {
      context.error(context.source.element(node).attribute("mpi-ranks"),
                    "mpi-ranks names '" + type.mpiRanksParam + "', which is not an int " +
                        "parameter of '" + type.type + "'");
    }
  }
  type.mpiJobParam = reader.text("mpi-job");
  if (!type.mpiJobParam.empty()) {
    const ParamSpec* param = type.findParam(type.mpiJobParam);
    if (param == nullptr || param->type != ParamType::String) {
      context.error(context.source.element(node).attribute("mpi-job"),
                    "mpi-job names '" + type.mpiJobParam + "', which is not a string " +
                        "parameter of '" + type.type + "'");
    }
  }
  addImplicitPorts(type);
  return type;
}

}  // namespace

void addImplicitPorts(ModuleType& type) {
  if (type.findPort(kBeginItPort) == nullptr) {
    PortSpec beginIt;
    beginIt.name = std::string(kBeginItPort);
    beginIt.isInput = true;
    beginIt.stampsOnly = true;
    beginIt.doc = "when connected, each iteration also waits for a message here";
    type.ports.push_back(std::move(beginIt));
  }
  if (type.findPort(kEndItPort) == nullptr) {
    PortSpec endIt;
    endIt.name = std::string(kEndItPort);
    endIt.isInput = false;
    endIt.stampsOnly = true;
    endIt.doc = "a stamps-only message each time the module finishes an iteration";
    type.ports.push_back(std::move(endIt));
  }
}

Result<PackageManifest> readPackageManifest(std::string_view xml, const std::string& fileName) {
  try {
    const SourceText source(xml, fileName);
    pugi::xml_document document;
    const pugi::xml_parse_result parsed =
        document.load_buffer(xml.data(), xml.size(), pugi::parse_default, pugi::encoding_utf8);
    if (!parsed) return makeError(formatDiagnostic(parseFailure(source, parsed)));

    std::vector<Diagnostic> problems;
    const ReadContext context{source, problems};
    PackageManifest manifest;
    manifest.file = fileName;
    const pugi::xml_node root = document.document_element();
    if (std::string_view(root.name()) != "package") {
      context.error(source.element(root),
                    "root element must be <package>, found <" + std::string(root.name()) + ">");
    } else {
      const ElementReader reader(context, root, {"name", "version"});
      manifest.name = reader.required("name");
      manifest.version = reader.text("version");
      if (manifest.name.find_first_of("/ \t\n") != std::string::npos) {
        reader.errorAt("name",
                       "package name '" + manifest.name + "' must not contain '/' or spaces");
      }
      forEachChild(context, root, {"doc", "module"}, [&](const pugi::xml_node& child) {
        if (std::string_view(child.name()) == "doc") {
          const ElementReader docReader(context, child, {});
          manifest.doc = readTextElement(context, child);
          return;
        }
        ModuleType type = readModuleType(context, child, manifest.name);
        for (const ModuleType& previous : manifest.modules) {
          if (!type.type.empty() && previous.type == type.type) {
            context.error(source.element(child).attribute("type"),
                          "module type '" + type.type + "' is declared twice (first at line " +
                              std::to_string(previous.loc.line) + ")");
          }
        }
        manifest.modules.push_back(std::move(type));
      });
    }
    if (!problems.empty()) {
      sortAndDeduplicate(problems);
      std::string message = formatDiagnostics(problems);
      message.pop_back();
      return makeError(std::move(message));
    }
    return manifest;
  } catch (const std::exception& e) {
    return makeError(fileName + ": error: cannot read package manifest (" + e.what() + ")");
  }
}

}  // namespace vrflow::app::detail
