#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/app/source_location.hpp"
#include "vrflow/base/parameters.hpp"

namespace vrflow::app {

/// The data type that matches every other one.
inline constexpr std::string_view kAnyData = "any";
/// The implicit input every module has: when connected, each iteration also waits on it.
inline constexpr std::string_view kBeginItPort = "beginIt";
/// The implicit output every module has: a stamps-only message per finished iteration.
inline constexpr std::string_view kEndItPort = "endIt";

/// A port declared by a module or filter type.
struct PortSpec {
  std::string name;
  bool isInput = true;
  std::string data = std::string(kAnyData);  ///< data type name; "any" matches all
  bool stampsOnly = false;                   ///< carries stamps without payload
  bool required = false;                     ///< inputs only: must be connected
  /// Filter inputs only: false for a control input that the filter emits without (a route's
  /// interest, a gate's open), so a cycle through it needs no initial message.
  bool gating = true;
  std::string doc;
};

/// The value types of parameters (vrflow/base/parameters.hpp).
using vrflow::ParamType;
using vrflow::parseParamType;
using vrflow::toString;

/// What a module does with the path a file parameter names (manifest attribute `access`).
enum class FileAccess {
  Unstated,  ///< not declared: no check of the path
  Input,     ///< read: must be a regular file
  Output,    ///< written (a file, or a folder for a folder-valued parameter): its parent folder
             ///< must exist unless it lies inside the run's working folder
};

/// A parameter declared by a module or filter type.
struct ParamSpec {
  std::string name;
  ParamType type = ParamType::String;
  std::string defaultValue;
  std::optional<double> min;                 ///< int, float, vec3 (each component)
  std::optional<double> max;                 ///< int, float, vec3 (each component)
  std::vector<std::string> choices;          ///< enum only
  FileAccess access = FileAccess::Unstated;  ///< file only
  std::string doc;
};

/// What a module is for, as drawn by the editor.
enum class ModuleKind { Animator, Interactor, Viewer, Input, Other };

/// A module type of a node package, read from its vrflow-package.xml.
struct ModuleType {
  std::string package;
  std::string type;
  /// Absolute for a path written with a '/' (resolved against the manifest's folder) or a bare
  /// name found in the package's folder, its layout's `bin` folder or beside the running
  /// program (docs/application-format.md, "Package manifests"); else the bare name as written.
  std::string executable;
  /// The folders a bare name was looked for in when none held it (checkModuleFiles() reports
  /// them); empty when `executable` was resolved.
  std::vector<std::string> executableSearched;
  /// A script module's script (manifest attribute `script`), absolute; empty for a program.
  /// `executable` is then the script's interpreter (attribute `interpreter`, default python3),
  /// looked up on PATH when the module starts (docs/python.md).
  std::string script;
  ModuleKind kind = ModuleKind::Other;
  /// Empty, or the name of an int parameter: when a module's value of it is N > 1, the runtime
  /// starts the module as N MPI ranks through `mpirun` (rank 0 is the module vrflow talks to;
  /// the others are its workers). Manifest attribute `mpi-ranks`.
  std::string mpiRanksParam;
  /// Empty, or the name of a string parameter: modules of this type whose value of it is the
  /// same non-empty text form one MPI job named by it, one module per rank (rank r is the r-th
  /// of them in the application's module order; see mpi_job.hpp). The runtime starts a job of
  /// N >= 2 modules as one `mpirun -np N`. Manifest attribute `mpi-job`.
  std::string mpiJobParam;
  std::string doc;
  std::vector<PortSpec> ports;  ///< declared ports, then beginIt and endIt
  std::vector<ParamSpec> params;
  SourceLocation loc;  ///< the <module> element in the manifest

  /// The port with this name, or nullptr.
  const PortSpec* findPort(std::string_view name) const;
  /// The parameter with this name, or nullptr.
  const ParamSpec* findParam(std::string_view name) const;
};

/// A filter type: run by the daemon; its ports may depend on its parameters.
struct FilterType {
  std::string name;
  std::string doc;
  std::vector<ParamSpec> params;
  /// The ports of a filter with these parameter values (values already validated or not: it
  /// must cope with bad ones by using defaults).
  std::function<std::vector<PortSpec>(const std::vector<Param>&)> ports;
  /// How many messages the filter emits at start-up without input (what breaks a cycle);
  /// empty means none.
  std::function<int(const std::vector<Param>&)> initialMessages;
  /// Problems the parameters have together (a list whose length must match a count, ...):
  /// a message, or nullopt when they fit. Empty means no such rule. Must cope with bad values.
  std::function<std::optional<std::string>(const std::vector<Param>&)> check;

  /// The ports for these parameters (none when `ports` is empty).
  std::vector<PortSpec> portsFor(const std::vector<Param>& values) const;
  /// The start-up message count for these parameters (0 when `initialMessages` is empty).
  int initialMessagesFor(const std::vector<Param>& values) const;
  /// The parameter with this name, or nullptr.
  const ParamSpec* findParam(std::string_view paramName) const;
};

/// "input", "output" or "" (unstated).
std::string toString(FileAccess access);
/// The access written `text` ("input" or "output"), or nullopt.
std::optional<FileAccess> parseFileAccess(std::string_view text);
/// "animator", "interactor", "viewer", "input" or "other".
std::string toString(ModuleKind kind);
/// The kind written `text`, or nullopt.
std::optional<ModuleKind> parseModuleKind(std::string_view text);

/// Why `value` is not a valid value of parameter `spec` ("expects an int, got 'x'", "is above
/// its maximum 10", ...), or nullopt when it is valid: the type's parser (parseParamValue), then
/// the declaration's range or choices.
std::optional<std::string> checkParamValue(const ParamSpec& spec, std::string_view value);

/// The typed value of `text` for `spec`, or why it is not valid (checkParamValue's message).
Result<ParamValue> parseParamValue(const ParamSpec& spec, std::string_view text);

/// The typed parameter set of one module or filter owned by `owner`: each of `specs` with its
/// value in `values` (already validated) or else its default; a parameter with neither (an
/// empty default of an int, float, bool or vec3) is declared without a value. Fails on a value
/// that is not valid or a name that is not declared (the validator refuses both first).
Result<Parameters> parameterSet(const std::vector<ParamSpec>& specs,
                                const std::vector<Param>& values, std::string owner);

/// The port with this name in `ports`, or nullptr.
const PortSpec* findPort(const std::vector<PortSpec>& ports, std::string_view name);

}  // namespace vrflow::app
