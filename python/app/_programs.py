"""Where the package finds vrflow's programs and what ships with them, and how it runs them.

The package knows its tree: `_layout.BIN_DIR` (written by CMake) leads from the package's folder
to the build tree's or the installed tree's `bin/`. vrflow's programs find the tree's packages,
composites and filter plugins from their own folder; inside the interpreter, the library is told
that folder (`_app.set_executable_dir`) when the package is imported, so that it searches what
`vrflow` searches, in the same order."""

import json
import os
import signal
import subprocess
import tempfile

from . import _app, _layout
from ._errors import RunError, VrflowError

#: The folder of vrflow's programs (`vrflow`, `vrflow-daemon`, the modules).
BIN_DIR = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                        _layout.BIN_DIR))
_app.set_executable_dir(BIN_DIR)


def program(name="vrflow"):
    """The path of vrflow's program `name`; VrflowError when the tree has none."""
    path = os.path.join(BIN_DIR, name)
    if not os.access(path, os.X_OK):
        raise VrflowError(f"{path}: no such program; the vrflow Python package expects "
                          f"vrflow's programs in {BIN_DIR} (build them, or install the tree)")
    return path


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
