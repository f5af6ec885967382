#include "vrflow/app/package_files.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <set>
#include <system_error>

#include "vrflow/base/echo.hpp"
#include "vrflow/base/file_access.hpp"

namespace vrflow::app {
namespace {

namespace fs = std::filesystem;

std::string moduleLabel(const Module& module) {
  return "module " + quotedValue(module.id) + " (" + module.package + "/" + module.type + ")";
}

// Where the module will look for an input: beside the application file when it is there, else
// relative to the working folder (the daemon's rule for file parameters).
std::string inputPath(const std::string& value, const Application& app) {
  const fs::path path(value);
  if (path.is_absolute() || app.file.empty()) return value;
  const fs::path beside = fs::path(app.file).parent_path() / path;
  std::error_code ignored;
  return fs::is_regular_file(beside, ignored) ? beside.lexically_normal().string() : value;
}

void checkFileParam(const ParamSpec& spec, const std::string& value, const SourceLocation& loc,
                    const Module& module, const Application& app,
                    std::vector<Diagnostic>& problems) {
  if (spec.type != ParamType::File || value.empty()) return;
  const std::string what =
      "parameter '" + spec.name + "' of " + moduleLabel(module) + " names " + quotedValue(value);
  if (spec.access == FileAccess::Input) {
    if (Status regular = checkRegularFile(inputPath(value, app)); !regular) {
      problems.push_back(
          {loc, Diagnostic::Error,
           what + ", an input that must be a regular file (" + regular.error().message + ")"});
    }
  } else if (spec.access == FileAccess::Output) {
    if (Status writable = checkOutputPath(value); !writable) {
      problems.push_back(
          {loc, Diagnostic::Error,
           what + ", an output that cannot be written: " + writable.error().message});
    }
  }
}

void checkExecutable(const ModuleType& type, const Module& module,
                     std::vector<Diagnostic>& problems) {
  std::string manifest = type.loc.file;
  if (type.loc.line > 0) manifest += ":" + std::to_string(type.loc.line);
  if (!type.executableSearched.empty()) {  // a bare name found in none of its folders
    std::string folders;
    for (const std::string& folder : type.executableSearched) {
      folders += (folders.empty() ? "" : ", ") + folder;
    }
    problems.push_back({module.loc, Diagnostic::Error,
                        moduleLabel(module) + ": no executable " + quotedValue(type.executable) +
                            " (declared at " + manifest + ") in the package's folder, its " +
                            "layout's bin folder or beside this program; looked in " + folders});
    return;
  }
  if (!type.script.empty()) {  // run by its interpreter, looked up on PATH as it starts
    if (::access(type.script.c_str(), R_OK) == 0) return;
    const std::string reason = std::strerror(errno);
    problems.push_back({module.loc, Diagnostic::Error,
                        moduleLabel(module) + ": cannot read its script " +
                            quotedValue(type.script) + " (" + reason + "), resolved from " +
                            manifest + " against the manifest's folder"});
    return;
  }
  if (type.executable.find('/') == std::string::npos) return;  // a manifest without a file
  if (::access(type.executable.c_str(), X_OK) == 0) return;
  const std::string reason = std::strerror(errno);
  problems.push_back({module.loc, Diagnostic::Error,
                      moduleLabel(module) + ": cannot start its executable " +
                          quotedValue(type.executable) + " (" + reason + "), resolved from " +
                          manifest + " against the manifest's folder"});
}

}  // namespace

std::vector<Diagnostic> checkModuleFiles(const Application& app, const Catalog& catalog,
                                         const ModuleFileChecks& checks) {
  std::vector<Diagnostic> problems;
  std::set<const ModuleType*> executablesChecked;
  for (const Module& module : app.modules) {
    const ModuleType* type = catalog.findModule(module.package, module.type);
    if (type == nullptr) continue;  // validate() reports it
    for (const ParamSpec& spec : type->params) {
      const Param* set = findParam(module.params, spec.name);
      const SourceLocation loc = set != nullptr ? set->loc.attribute("value") : module.loc;
      checkFileParam(spec, set != nullptr ? set->value : spec.defaultValue, loc, module, app,
                     problems);
    }
    if (checks.executables && executablesChecked.insert(type).second) {
      checkExecutable(*type, module, problems);
    }
  }
  for (Diagnostic& problem : problems) problem.loc.attributes.clear();
  return problems;
}

}  // namespace vrflow::app
