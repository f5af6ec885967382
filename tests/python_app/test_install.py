"""`cmake --install` puts the Python package into the interpreter's package folder under the
prefix; with only that folder on PYTHONPATH (and the tree moved elsewhere) it imports, finds the
installed programs and node packages with no option, builds, validates and runs an application.
Like the install tests (label install), it installs the whole build: build everything first."""

import glob
import os
import shutil
import subprocess
import sys

from conftest import BUILD_DIR

SCRIPT = r"""
import os, sys
from vrflow import app
assert app.__file__.startswith(sys.argv[1]), app.__file__
assert app.BIN_DIR == os.path.join(sys.argv[1], "bin"), app.BIN_DIR
a = app.Application("installed", os.path.join(sys.argv[2], "installed.xml"))
src = a.module("src", "core/source", size=64)
sink = a.module("sink", "core/recorder", file="received.csv")
a.connect(src.out, sink.in_)
a.check()
broken = app.Application("broken")
broken.module("s", "core/sourse")
print(broken.validate().text, end="")
print(a.run(iterations=3, cwd=sys.argv[2])["status"])
"""


def test_the_installed_package_imports_validates_and_runs_from_its_prefix(tmp_path):
    first = tmp_path / "first"
    done = subprocess.run(["cmake", "--install", BUILD_DIR, "--prefix", str(first)],
                          capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    prefix = tmp_path / "prefix"
    shutil.move(first, prefix)  # the installed tree is relocatable
    found = glob.glob(str(prefix / "lib" / "python3*" / "*-packages" / "vrflow" / "app.py"))
    assert len(found) == 1, os.listdir(prefix / "lib")
    site = os.path.dirname(os.path.dirname(found[0]))
    work = tmp_path / "work"
    work.mkdir()
    environment = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "PYTHONPATH": site,
                   "PYTHONDONTWRITEBYTECODE": "1", "XDG_STATE_HOME": str(tmp_path / "state")}
    ran = subprocess.run([sys.executable, "-c", SCRIPT, str(prefix), str(work)], cwd=work,
                         env=environment, capture_output=True, text=True, timeout=120,
                         check=False)
    assert ran.returncode == 0, ran.stderr
    assert ran.stdout.splitlines() == [
        "broken.xml:4:35: error: unknown module type 'core/sourse' (known in package core: "
        "gravity, points, recorder, relay, source, spring); did you mean 'source'?",
        "ok"]
