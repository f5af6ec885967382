"""Where the package finds vrflow's programs and what ships with them, and how it runs them.

The package knows its tree: `_layout.BIN_DIR` (written by CMake) leads from the package's folder
to the build tree's or the installed tree's `bin/`, beside `share/vrflow/packages`,
`share/vrflow/composites` and `lib/vrflow/filters`, which `vrflow` itself finds from its own
folder. Checks done in this process add those folders to the search path variables for the
call, after what the variables already hold, which is the order `vrflow` searches them in."""

import contextlib
import json
import os
import signal
import subprocess
import sys
import tempfile

from . import _layout
from ._errors import RunError, VrflowError

#: The folder of vrflow's programs (`vrflow`, `vrflow-daemon`, the modules).
BIN_DIR = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                        _layout.BIN_DIR))

# Each search path variable and the folder of the tree it gets last.
_SEARCH_PATHS = {
    "VRFLOW_PACKAGE_PATH": os.path.join("share", "vrflow", "packages"),
    "VRFLOW_COMPOSITE_PATH": os.path.join("share", "vrflow", "composites"),
    "VRFLOW_FILTER_PATH": os.path.join("lib", "vrflow", "filters"),
}


def program(name="vrflow"):
    """The path of vrflow's program `name`; VrflowError when the tree has none."""
    path = os.path.join(BIN_DIR, name)
    if not os.access(path, os.X_OK):
        raise VrflowError(f"{path}: no such program; the vrflow Python package expects "
                          f"vrflow's programs in {BIN_DIR} (build them, or install the tree)")
    return path


@contextlib.contextmanager
def tree_search_paths():
    """Adds this tree's packages, composites and filter plugins to the search path variables
    for the duration of the block (the library finds them from the running program's folder,
    which is the interpreter's here)."""
    root = os.path.dirname(BIN_DIR)
    interpreter_root = os.path.dirname(os.path.dirname(os.path.realpath(sys.executable)))
    saved = {name: os.environ.get(name) for name in _SEARCH_PATHS}
    try:
        if os.path.realpath(root) != interpreter_root:
            for name, folder in _SEARCH_PATHS.items():
                parts = [p for p in (saved[name] or "").split(":") if p]
                os.environ[name] = ":".join(parts + [os.path.join(root, folder)])
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


def run_program(command, path, arguments, cwd=None):
    """Runs `vrflow COMMAND PATH ARGUMENTS... --report FILE --no-progress` and returns the report
    as a dict; RunError when it exits with another status than 0. Interrupted (Ctrl-C), the
    program is asked to stop as Ctrl-C asks it (SIGINT: it stops its modules and removes its
    shared memory) and waited for; it is never killed."""
    with tempfile.TemporaryDirectory(prefix="vrflow-python-") as folder:
        report_path = os.path.join(folder, "report.json")
        argv = [program(), command, path, *arguments, "--report", report_path, "--no-progress"]
        with subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) as process:
            try:
                _, stderr = process.communicate()
            except BaseException:
                process.send_signal(signal.SIGINT)
                process.communicate()
                raise
        report = None
        if os.path.exists(report_path):
            with open(report_path, encoding="utf-8") as file:
                report = json.load(file)
        if process.returncode != 0:
            raise RunError(command, process.returncode, report, stderr)
        return report
