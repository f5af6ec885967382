"""The builder scripts of the examples write their example's file in canonical form, byte for
byte (what saveApplication() writes for the hand-written file), and what they build is valid."""

import os
import shutil
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR, vrflow
from vrflow import app

EXAMPLES = ["pipeline", "paper_scene"]


def run_script(name, *arguments, cwd=None):
    script = os.path.join(SOURCE_DIR, "examples", name, f"{name}.py")
    return subprocess.run([sys.executable, script, *arguments], cwd=cwd, capture_output=True,
                          text=True, timeout=120, check=False)


@pytest.mark.parametrize("name", EXAMPLES)
def test_the_script_saves_the_canonical_form_of_the_example_file(name, tmp_path):
    out = tmp_path / f"{name}.xml"
    done = run_script(name, str(out))
    assert done.returncode == 0, done.stderr
    canonical = app.load(os.path.join(SOURCE_DIR, "examples", name, f"{name}.xml")).text()
    assert out.read_bytes() == canonical.encode("utf-8")
    printed = run_script(name)
    assert printed.stdout == canonical


@pytest.mark.parametrize("name", EXAMPLES)
def test_the_saved_file_is_valid_beside_the_examples_data(name, tmp_path):
    for data in os.listdir(os.path.join(SOURCE_DIR, "examples", name)):
        if data.endswith(".json"):
            shutil.copy(os.path.join(SOURCE_DIR, "examples", name, data), tmp_path)
    out = str(tmp_path / f"{name}.xml")
    assert run_script(name, out, "--validate").returncode == 0
    assert vrflow("validate", out) == (0, "")


def test_the_pipeline_script_runs_it(tmp_path):
    done = run_script("pipeline", "--run", "5", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert '"status": "ok"' in done.stdout
    assert os.path.isfile(tmp_path / "out" / "demo" / "trajectory.csv")
