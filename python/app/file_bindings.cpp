// Loading, saving and checking applications from Python: the loader, the writer and
// run::prepare(), the one path `vrflow validate|run|launch` take, so that a model built in
// Python gets the same diagnostics as the file it saves. Errors come back as values; the Python
// side (vrflow/app.py) turns them into exceptions.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "vrflow/app/composite_file.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/package_files.hpp"
#include "vrflow/app/writer.hpp"
#include "vrflow/base/executable_dir.hpp"
#include "vrflow/run/prepare.hpp"

namespace py = pybind11;

namespace vrflow::python {
namespace {

using app::Diagnostic;

// What prepare() found, for Python: the flat application when it is ready, and every problem.
struct Checked {
  std::optional<app::Application> application;
  std::vector<Diagnostic> diagnostics;
  std::string error;
  bool catalogFailed = false;
};

// Settings of one check: `text`, the canonical XML of the model, checked as if saved at `file`,
// or, without it, the file itself.
struct CheckRequest {
  std::optional<std::string> text;
  std::string file;
  std::vector<std::string> packageDirs;
  std::vector<std::string> compositeDirs;
  std::vector<std::string> overrides;
  bool validate = true;
  bool checkFiles = true;
};

Checked check(const CheckRequest& request) {
  run::PrepareSettings settings{.file = request.file,
                                .text = request.text,
                                .packageDirs = request.packageDirs,
                                .compositeDirs = request.compositeDirs,
                                .overrides = request.overrides,
                                .validate = request.validate,
                                .files = std::nullopt,
                                .program = "vrflow"};
  // What `vrflow validate` checks of the files the modules name (not their executables).
  if (request.checkFiles) settings.files = app::ModuleFileChecks{};
  run::Prepared prepared = run::prepare(settings);
  return Checked{std::move(prepared.application), std::move(prepared.diagnostics),
                 std::move(prepared.error), prepared.catalogFailed};
}

// A loaded value as Python gets it: (value, "") or (None, the error).
template <typename T>
std::pair<std::optional<T>, std::string> orError(Result<T> loaded) {
  if (!loaded) return {std::nullopt, loaded.error().message};
  return {std::move(*loaded), std::string()};
}

void bindDiagnostics(py::module_& module) {
  py::class_<Diagnostic>(module, "Diagnostic")
      .def_property_readonly("severity",
                             [](const Diagnostic& diagnostic) {
                               return diagnostic.severity == Diagnostic::Error ? "error"
                                                                               : "warning";
                             })
      .def_readonly("message", &Diagnostic::message)
      .def_property_readonly("file", [](const Diagnostic& d) { return d.loc.file; })
      .def_property_readonly("line", [](const Diagnostic& d) { return d.loc.line; })
      .def_property_readonly("column", [](const Diagnostic& d) { return d.loc.column; })
      .def("__str__",
           [](const Diagnostic& diagnostic) { return app::formatDiagnostic(diagnostic); });

  py::class_<Checked>(module, "Checked")
      .def_readonly("application", &Checked::application)
      .def_readonly("diagnostics", &Checked::diagnostics)
      .def_readonly("error", &Checked::error)
      .def_readonly("catalog_failed", &Checked::catalogFailed);
}

}  // namespace

void bindFiles(py::module_& module) {
  bindDiagnostics(module);
  module.def(
      "set_executable_dir", [](const std::string& folder) { setExecutableDir(folder); },
      py::arg("folder"),
      "Where the library finds the tree's programs and, from there, its packages, composites "
      "and filter plugins, as vrflow's programs do from their own folder");
  module.def(
      "load_application",
      [](const std::string& path) { return orError(app::loadApplicationFile(path)); },
      py::arg("path"), "The application in `path`, or (None, the error naming file:line)");
  module.def(
      "load_composite",
      [](const std::string& path) { return orError(app::loadCompositeFile(path)); },
      py::arg("path"), "The composite in `path` (NAME.vrc.xml), or (None, the error)");
  module.def("save_text", &app::saveApplication, py::arg("application"),
             "The canonical XML text of the application (what the editor opens)");
  module.def(
      "save_file",
      [](const app::Application& application, const std::string& path) {
        auto saved = app::saveApplicationFile(application, path);
        return saved ? std::string() : saved.error().message;
      },
      py::arg("application"), py::arg("path"), "Writes the canonical XML; the error or ''");
  module.def(
      "check",
      [](std::optional<std::string> text, std::string file, std::vector<std::string> packageDirs,
         std::vector<std::string> compositeDirs, std::vector<std::string> overrides, bool validate,
         bool checkFiles) {
        const CheckRequest request{std::move(text),
                                   std::move(file),
                                   std::move(packageDirs),
                                   std::move(compositeDirs),
                                   std::move(overrides),
                                   validate,
                                   checkFiles};
        py::gil_scoped_release unlocked;
        return check(request);
      },
      py::arg("text"), py::arg("file"), py::arg("package_dirs"), py::arg("composite_dirs"),
      py::arg("overrides"), py::arg("validate") = true, py::arg("check_files") = true,
      "run::prepare() on `text` as if saved at `file` (None: on the file): load, expand, --set, "
      "plugins, validate");
}

}  // namespace vrflow::python
