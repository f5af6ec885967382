"""run() and launch() go through the real `vrflow` program and give back its report as a dict;
a failed or invalid run is a RunError carrying the status, the report and the diagnostics."""

import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import vrflow
from vrflow import app


def source_to_recorder(name, path=None, count=0):
    a = app.Application(name, path)
    src = a.module("src", "core/source", count=count, size=64)
    relay = a.module("relay", "core/relay")
    sink = a.module("sink", "core/recorder", file="out/received.csv")
    a.connect(src.out, relay.in_)
    a.connect(relay.out, sink.in_)
    return a


def processes_in(folder):
    """The processes working in `folder`: the runtime, daemons and modules of a run started
    there, while they live (their shared memory is memfd, owned by them)."""
    found = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            if os.readlink(f"/proc/{pid}/cwd") == str(folder):
                found.append(pid)
        except OSError:
            pass
    return found


def test_run_returns_the_report_of_vrflow_run(tmp_path):
    a = source_to_recorder("python run")
    report = a.run(iterations=20, cwd=tmp_path)
    assert report["format"] == "vrflow-run-report/1"
    assert (report["status"], report["exit_code"], report["error"]) == ("ok", 0, "")
    assert {m["id"]: m["iterations"] for m in report["modules"]} == {
        "src": 20, "relay": 20, "sink": 20}
    assert os.path.isfile(tmp_path / "out" / "received.csv")
    assert a.path is None  # an application never saved ran from a temporary file
    assert processes_in(tmp_path) == []


def test_run_saves_the_application_at_its_path_first(tmp_path):
    a = source_to_recorder("saved", tmp_path / "saved.xml")
    report = a.run(iterations=3, cwd=tmp_path)
    path = str(tmp_path / "saved.xml")
    assert (a.path, report["file"]) == (path, path)
    assert open(path, encoding="utf-8").read() == a.text()


def test_an_invalid_application_is_a_run_error_with_vrflows_diagnostics(tmp_path):
    path = str(tmp_path / "invalid.xml")
    a = app.Application("invalid", path)
    a.module("sink", "core/recorder")
    with pytest.raises(app.RunError) as raised:
        a.run(iterations=1, cwd=tmp_path)
    error = raised.value
    assert (error.exit_code, error.status, error.report) == (2, "invalid", None)
    status, printed = vrflow("validate", path)
    assert error.diagnostics == printed.splitlines()
    assert error.diagnostics == a.validate().text.splitlines()


def test_a_run_that_times_out_is_a_run_error_with_its_report(tmp_path):
    a = source_to_recorder("endless")
    with pytest.raises(app.RunError) as raised:
        a.run(timeout=1, cwd=tmp_path)
    error = raised.value
    assert (error.exit_code, error.status) == (3, "timeout")
    assert error.report["status"] == "timeout"
    assert "status 3 (timeout)" in str(error)
    assert processes_in(tmp_path) == []


def test_bad_run_options_are_errors_naming_them(tmp_path):
    a = source_to_recorder("options")
    with pytest.raises(app.RunError) as raised:
        a.run(iterations=-1, cwd=tmp_path)
    assert raised.value.exit_code == 2
    assert "--iterations" in raised.value.stderr
    relative = app.Application("relative")
    relative.packages("pkgs")
    with pytest.raises(ValueError, match="relative package folders"):
        relative.run(iterations=1)


def test_launch_returns_the_merged_report_of_two_hosts(tmp_path):
    path = str(tmp_path / "two_hosts.xml")
    a = app.Application("python launch", path)
    first = a.host("a")
    second = a.host("b")
    src = a.module("src", "core/source", first, size=64)
    sink = a.module("sink", "core/recorder", second, file="out/received.csv")
    a.connect(src.out, sink.in_)
    hosts = tmp_path / "hosts"
    hosts.write_text("a address=127.0.62.1\nb address=127.0.62.2\n")
    report = a.launch(iterations=5, hosts=hosts, cwd=tmp_path)
    assert report["status"] == "ok"
    assert report["timing"]["hosts"] == 2
    assert {m["id"]: (m["host"], m["iterations"]) for m in report["modules"]} == {
        "src": ("a", 5), "sink": ("b", 5)}
    assert processes_in(tmp_path) == []


def test_a_launch_with_a_bad_host_file_is_a_run_error_naming_its_line(tmp_path):
    a = source_to_recorder("bad hosts", str(tmp_path / "bad.xml"))
    hosts = tmp_path / "hosts"
    hosts.write_text("localhost adress=127.0.62.1\n")
    with pytest.raises(app.RunError) as raised:
        a.launch(iterations=1, hosts=hosts, cwd=tmp_path)
    assert raised.value.exit_code == 2
    assert f"{hosts}:1" in raised.value.stderr


INTERRUPTED_SCRIPT = r"""
import sys
from vrflow import app
a = app.Application("interrupted")
src = a.module("src", "core/source", size=64)
sink = a.module("sink", "core/recorder", file="received.csv")
a.connect(src.out, sink.in_)
try:
    a.run(cwd=sys.argv[1], log_dir=sys.argv[1] + "/logs")
except KeyboardInterrupt:
    print("interrupted")
"""


def test_ctrl_c_during_run_stops_the_run_and_leaves_nothing_behind(tmp_path):
    script = subprocess.Popen([sys.executable, "-c", INTERRUPTED_SCRIPT, str(tmp_path)],
                              stdout=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not os.path.exists(tmp_path / "received.csv") and time.monotonic() < deadline:
        time.sleep(0.05)
    assert os.path.exists(tmp_path / "received.csv"), "the run did not start"
    script.send_signal(signal.SIGINT)  # to the interpreter only, not to vrflow
    output, _ = script.communicate(timeout=60)
    assert (script.returncode, output) == (0, "interrupted\n")
    # vrflow was asked to stop as Ctrl-C asks it (not killed), and stopped its run.
    with open(tmp_path / "logs" / "vrflow.log", encoding="utf-8") as log:
        assert "interrupted by SIGINT" in log.read()
    assert processes_in(tmp_path) == []
