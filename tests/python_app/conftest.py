"""Shared by the application builder's tests: the build tree, the source tree, and `vrflow`
itself to compare with (tests/python_app/CMakeLists.txt sets the environment)."""

import os
import subprocess

import pytest

BUILD_DIR = os.environ["VRFLOW_BUILD_DIR"]
SOURCE_DIR = os.environ["VRFLOW_SOURCE_DIR"]
VRFLOW = os.path.join(BUILD_DIR, "bin", "vrflow")


def vrflow(*arguments, cwd=None):
    """Runs the real `vrflow` program; returns (exit status, stderr)."""
    done = subprocess.run([VRFLOW, *arguments], cwd=cwd, stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, timeout=120, check=False)
    return done.returncode, done.stderr


@pytest.fixture(autouse=True)
def own_search_paths(monkeypatch):
    """Each test sees only the build's packages, composites and filters."""
    for name in ("VRFLOW_PACKAGE_PATH", "VRFLOW_COMPOSITE_PATH", "VRFLOW_FILTER_PATH"):
        monkeypatch.delenv(name, raising=False)
