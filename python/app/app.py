"""Build, check, save, run and launch vrflow applications from Python.

    from vrflow import app

    a = app.Application("demo")
    local = a.host("local")
    src = a.module("src", "core/source", local, count=10)
    sink = a.module("sink", "core/sink", local)
    a.connect(src.out, sink.in_)
    a.check()              # ValidationError with vrflow validate's diagnostics
    a.save("demo.xml")     # the canonical XML, what the editor opens
    report = a.run(iterations=10)   # the run report as a dict

The model is vrflow's own (vrflow::app through the extension vrflow._app): loading, saving and
validating are the library's, so what a script builds is what `vrflow` reads. Runs go through the
`vrflow` program (docs/python-apps.md says why). The reference is docs/python-apps.md."""

import argparse
import json
import os
import sys
import tempfile

from . import _app
from ._builder import Node, Port, Ports, Scope, comment_list, endpoint, param_text
from ._errors import LoadError, RunError, ValidationError, VrflowError
from ._programs import BIN_DIR, program, run_program

__all__ = ["Application", "Validation", "Node", "Port", "Ports", "load", "load_composite", "main",
           "VrflowError", "LoadError", "ValidationError", "RunError", "BIN_DIR", "program",
           "param_text", "endpoint"]

# `vrflow validate`, `run`, `expand` and `launch` print at most this many problems.
_MAX_PRINTED = 20


class Validation:
    """What checking an application found: `diagnostics` (each with severity, message, file,
    line, column; str() is its line), `error` (a problem that stopped the check early, such as
    the node packages that could not be loaded), `ok` (nothing of severity error), and `text`,
    what `vrflow validate` prints for the same file."""

    def __init__(self, checked):
        self.diagnostics = list(checked.diagnostics)
        self.error = checked.error
        self.catalog_failed = checked.catalog_failed
        self.ok = checked.application is not None
        self._flat = checked.application

    @property
    def errors(self):
        """The diagnostics of severity error."""
        return [d for d in self.diagnostics if d.severity == "error"]

    @property
    def warnings(self):
        """The diagnostics of severity warning."""
        return [d for d in self.diagnostics if d.severity == "warning"]

    @property
    def text(self):
        """The lines `vrflow validate` prints: the error alone when there is one, else the first
        20 diagnostics and how many more there are."""
        if self.error:
            return self.error + "\n"
        lines = [str(d) for d in self.diagnostics[:_MAX_PRINTED]]
        if len(self.diagnostics) > _MAX_PRINTED:
            lines.append(f"... and {len(self.diagnostics) - _MAX_PRINTED} more problems")
        return "".join(line + "\n" for line in lines)

    def __str__(self):
        return self.text

    def __repr__(self):
        return f"<Validation ok={self.ok} diagnostics={len(self.diagnostics)}>"


class Application(Scope):
    """A vrflow application being built (or loaded): hosts, package folders, modules, filters,
    composite instances, connections and editor layout, in the order they are added, which is
    the order the file lists them in.

    `path` is where the application lives: the file load() read or save() wrote last. Relative
    paths in it (package folders, file parameters) are taken from its folder, and its
    diagnostics name it; an application never saved is checked as `NAME.xml` in the working
    folder."""

    def __init__(self, name="", path=None, *, comment=None):
        super().__init__(_app.Application())
        self.model.name = name
        self.model.comments = comment_list(comment)
        self.path = os.fspath(path) if path is not None else None

    @property
    def model(self):
        """The C++ model (vrflow::app::Application) the builder fills; its lists are live."""
        return self._model

    @property
    def name(self):
        """The application's name (`<application name>`)."""
        return self._model.name

    def host(self, host_id, address="127.0.0.1", comment=None):
        """Adds host `host_id` at `address`; returns its id, to give as `host=` of nodes. The
        first host is where nodes without a host run."""
        host = _app.Host()
        host.id = host_id
        host.address = address
        host.comments = comment_list(comment)
        self._model.hosts.append(host)
        return host_id

    def packages(self, folder, comment=None):
        """Adds `<packages path=folder>`: a folder of node packages, relative to the
        application file's folder."""
        entry = _app.PackageFolder(str(folder))
        entry.comments = comment_list(comment)
        self._model.packages.append(entry)

    def define(self, composite_file):
        """Copies the composite of `composite_file` (NAME.vrc.xml) into the application's
        `<composites>` section, so that the file carries it; returns its name."""
        composite = load_composite(composite_file)
        self._model.composites.append(composite)
        return composite.name

    def note(self, note_id, text, x=0, y=0, width=200, height=80):
        """Adds a note to the editor's canvas."""
        note = _app.EditorNote()
        note.id, note.text = note_id, text
        note.x, note.y, note.width, note.height = float(x), float(y), float(width), float(height)
        self._model.notes.append(note)

    def frame(self, frame_id, title="", x=0, y=0, width=400, height=300, color=""):
        """Adds a titled frame to the editor's canvas (`color` written #rrggbb)."""
        frame = _app.EditorFrame()
        frame.id, frame.title, frame.color = frame_id, title, color
        frame.x, frame.y = float(x), float(y)
        frame.width, frame.height = float(width), float(height)
        self._model.frames.append(frame)

    def text(self):
        """The canonical XML of the application (saveApplication()): what save() writes."""
        return _app.save_text(self._model)

    def save(self, path=None):
        """Writes the canonical XML to `path` (default: the application's path), which becomes
        the application's path; returns it. The editor opens it; `vrflow` runs it."""
        path = os.fspath(path) if path is not None else self.path
        if path is None:
            raise ValueError(f"save() needs a path: application '{self.name}' has none yet")
        self._model.file = path
        error = _app.save_file(self._model, path)
        if error:
            raise VrflowError(error)
        self.path = path
        return path

    def _check_path(self):
        return self.path if self.path is not None else f"{self.name or 'application'}.xml"

    def _text_to_check(self, path):
        """None when the file at `path` holds this model (its diagnostics then point at the
        file's own lines, as written by hand), else the canonical text to check as if saved
        there."""
        text = self.text()
        if os.path.isfile(path):
            on_disk, _ = _app.load_application(path)
            if on_disk is not None and _app.save_text(on_disk) == text:
                return None
        return text

    def validate(self, packages=(), composites=(), set=None):  # noqa: A002 (vrflow's --set)
        """Checks the application as `vrflow validate PATH` checks its file, with `packages` and
        `composites` as --packages and --composites folders and `set` as --set ID.PARAM=VALUE
        settings ({"id.param": value}); returns a Validation. When the file at its path holds
        another model (or none), the text save() would write there is checked."""
        path = self._check_path()
        self._model.file = path
        overrides = [f"{key}={param_text(value)}" for key, value in (set or {}).items()]
        checked = _app.check(self._text_to_check(path), path, [os.fspath(p) for p in packages],
                             [os.fspath(c) for c in composites], overrides)
        return Validation(checked)

    def check(self, **options):
        """validate(), raising ValidationError when the application is invalid; returns the
        Validation (which may hold warnings) otherwise."""
        validation = self.validate(**options)
        if not validation.ok:
            raise ValidationError(validation)
        return validation

    def expand(self, composites=(), set=None):  # noqa: A002
        """The flat application `vrflow expand` prints (composite instances replaced by their
        nodes, --set applied), as a new Application; ValidationError when that fails."""
        path = self._check_path()
        overrides = [f"{key}={param_text(value)}" for key, value in (set or {}).items()]
        checked = _app.check(self.text(), path, [], [os.fspath(c) for c in composites],
                             overrides, validate=False, check_files=False)
        if checked.application is None:
            raise ValidationError(Validation(checked))
        flat = Application()
        flat._model = checked.application
        return flat

    def _run(self, command, arguments, cwd):
        if self.path is not None:
            return run_program(command, os.path.abspath(self.save()), arguments, cwd)
        if any(not os.path.isabs(folder.path) for folder in self._model.packages):
            raise ValueError(f"application '{self.name}' names relative package folders, taken "
                             "from its file's folder: save() it before running it")
        with tempfile.TemporaryDirectory(prefix="vrflow-python-app-") as folder:
            path = os.path.join(folder, f"{self.name or 'application'}.xml")
            error = _app.save_file(self._model, path)
            if error:
                raise VrflowError(error)
            return run_program(command, path, arguments, cwd)

    def run(self, iterations=None, *, timeout=None, packages=(), composites=(), set=None,  # noqa: A002
            log_dir=None, cwd=None, args=()):
        """Runs the application on this machine with `vrflow run` and returns its report
        (docs/report.md) as a dict; RunError (status, report, diagnostics) when it fails. It is
        saved at its path first; one never saved runs from a temporary file. Folders and files
        given here are taken from Python's working folder; the run works in `cwd` (default:
        the same). `args` are more options of `vrflow run`."""
        arguments = _common_arguments(packages, composites, set, log_dir)
        if iterations is not None:
            arguments += ["--iterations", str(iterations)]
        if timeout is not None:
            arguments += ["--timeout", param_text(timeout)]
        return self._run("run", arguments + list(args), cwd)

    def launch(self, iterations=None, *, timeout=None, hosts=None, backend=None, packages=(),
               composites=(), set=None, log_dir=None, cwd=None, args=()):  # noqa: A002
        """Launches the application on its hosts with `vrflow launch` (docs/launcher.md) and
        returns the merged report as a dict; RunError when it fails. `hosts` is a host file,
        `backend` the launch backend; `args` are more options of `vrflow launch`."""
        arguments = _common_arguments(packages, composites, set, log_dir)
        if iterations is not None:
            arguments += ["--iterations", str(iterations)]
        if timeout is not None:
            arguments += ["--timeout", param_text(timeout)]
        if hosts is not None:
            arguments += ["--hosts", os.path.abspath(os.fspath(hosts))]
        if backend is not None:
            arguments += ["--backend", backend]
        return self._run("launch", arguments + list(args), cwd)


def _common_arguments(packages, composites, settings, log_dir):
    arguments = []
    for folder in packages:
        arguments += ["--packages", os.path.abspath(os.fspath(folder))]
    for folder in composites:
        arguments += ["--composites", os.path.abspath(os.fspath(folder))]
    for key, value in (settings or {}).items():
        arguments += ["--set", f"{key}={param_text(value)}"]
    if log_dir is not None:
        arguments += ["--log-dir", os.path.abspath(os.fspath(log_dir))]
    return arguments


def load(path):
    """The application in the file `path`, to change, check, save or run; LoadError (naming
    file:line) when it cannot be read or is malformed."""
    model, error = _app.load_application(os.fspath(path))
    if model is None:
        raise LoadError(error)
    application = Application(path=os.fspath(path))
    application._model = model
    return application


def load_composite(path):
    """The composite of a NAME.vrc.xml file (its name, ports and parameters); LoadError when it
    cannot be read."""
    composite, error = _app.load_composite(os.fspath(path))
    if composite is None:
        raise LoadError(error)
    return composite


def main(build, argv=None):
    """The command line of an application script whose `build()` returns an Application:
    `SCRIPT [OUT.xml] [--validate] [--run N]`. It saves the XML to OUT.xml (else prints it),
    prints the problems and exits 1 when --validate finds errors, and with --run N runs the
    application N iterations and prints the report (JSON), exiting with vrflow's status."""
    script_doc = (sys.modules[build.__module__].__doc__ or "").strip()
    parser = argparse.ArgumentParser(description=script_doc.split("\n")[0] or None)
    parser.add_argument("output", nargs="?", help="where to save the XML (default: print it)")
    parser.add_argument("--validate", action="store_true", help="check it as vrflow validate")
    parser.add_argument("--run", type=int, metavar="N", help="run it N iterations")
    options = parser.parse_args(argv)
    application = build()
    if options.output:
        application.save(options.output)
    elif not options.validate and options.run is None:
        sys.stdout.write(application.text())
    if options.validate:
        validation = application.validate()
        sys.stderr.write(validation.text)
        if not validation.ok:
            sys.exit(2 if validation.catalog_failed else 1)
    if options.run is not None:
        try:
            report = application.run(iterations=options.run)
        except RunError as error:
            sys.stderr.write(error.stderr)
            sys.exit(error.exit_code or 1)
        print(json.dumps(report, indent=2))
