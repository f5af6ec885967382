"""Runs real applications with the build's `vrflow` (VRFLOW_BUILD_DIR, set by ctest)."""

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
BUILD = Path(os.environ.get("VRFLOW_BUILD_DIR", HERE.parents[1] / "build"))
VRFLOW = BUILD / "bin" / "vrflow"


class Run:
    """A finished `vrflow run`: exit code, stderr, report, log folder."""

    def __init__(self, completed, report_file, log_dir):
        self.code = completed.returncode
        self.stderr = completed.stderr
        self.report = json.loads(report_file.read_text()) if report_file.exists() else None
        self.log_dir = log_dir

    def log(self, module):
        return (self.log_dir / f"{module}.log").read_text()

    def module(self, module_id):
        return next(m for m in self.report["modules"] if m["id"] == module_id)


@pytest.fixture
def package(tmp_path):
    """The test modules, copied into a folder of this test's own (its path names its processes)."""
    folder = tmp_path / "pytest-package"
    shutil.copytree(HERE / "modules", folder)
    return folder


def application(tmp_path, package, modules, connections):
    """Writes an application file: modules are (id, type, {param: value}), connections pairs."""
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', '<application name="pytest" version="1">',
             f'  <packages path="{package}"/>', "  <modules>"]
    for module_id, module_type, params in modules:
        lines.append(f'    <module id="{module_id}" package="pytest" type="{module_type}">')
        lines += [f'      <param name="{k}" value="{v}"/>' for k, v in params.items()]
        lines.append("    </module>")
    lines += ["  </modules>", "  <connections>"]
    lines += [f'    <connection from="{a}" to="{b}"/>' for a, b in connections]
    lines += ["  </connections>", "</application>"]
    path = tmp_path / "app.xml"
    path.write_text("\n".join(lines) + "\n")
    return path


def run(tmp_path, app, *args, timeout=120):
    """Runs `vrflow run APP` in tmp_path; checks that no process of the test is left behind."""
    report = tmp_path / "report.json"
    logs = tmp_path / "logs"
    completed = subprocess.run(
        [str(VRFLOW), "run", str(app), "--report", str(report), "--log-dir", str(logs),
         "--no-progress", *args],
        cwd=tmp_path, capture_output=True, text=True, timeout=timeout)
    left = subprocess.run(["pgrep", "-f", str(tmp_path)], capture_output=True, text=True)
    assert left.stdout == "", f"processes left behind: {left.stdout}"
    return Run(completed, report, logs)
