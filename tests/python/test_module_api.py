"""The Python module API in real runs: every chunk kind, zero copy, forwarding, errors."""

import json
import subprocess
import sys

from conftest import application, run

MIB16 = 16 * 1024 * 1024


def chain(tmp_path, package, **producer_params):
    return application(
        tmp_path, package,
        [("p", "producer", producer_params), ("f", "forwarder", {}),
         ("c", "checker", {"out": tmp_path / "checked.jsonl"})],
        [("p.out", "f.in"), ("f.out", "c.in")])


def test_every_chunk_kind_reaches_a_python_module_through_a_python_forwarder(tmp_path, package):
    result = run(tmp_path, chain(tmp_path, package, scale=2), "--iterations", "3")
    assert result.code == 0, result.stderr
    assert [m["iterations"] for m in result.report["modules"]] == [3, 3, 3]
    lines = [json.loads(x) for x in (tmp_path / "checked.jsonl").read_text().splitlines()]
    assert len(lines) == 3
    for i, line in enumerate(lines):
        assert line["source"] == "p"
        assert line["sim_time"] == 0.25 * i
        assert line["stamps"] == {"label": "hello", "flag": 1, "offset-y": 2.0}
        kinds = [(c["kind"], c.get("op") or c.get("resource") or c.get("event"))
                 for c in line["chunks"]]
        assert kinds == [("object", "add"), ("object", "delete"), ("resource", "mesh"),
                         ("resource", "scalar_field"), ("resource", "vector_field"),
                         ("event", 1), ("event", 1100), ("resource", "raw")]
        obj = line["chunks"][0]
        assert obj["type"] == "pytest-all"
        assert obj["params"] == {
            "s": 2.0 * i, "v": [1.0, 2.0, 3.0], "q": [0.0, 0.0, 0.0, 1.0],
            "m": [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            "box": [[-1.0, -2.0, -3.0], [1.0, 2.0, 3.0]], "ref": 42, "n": -5,
            "f": [0.0, 2.0, 4.0, 6.0], "d": [0.5, 0.25], "b": [97, 98, 99]}
        if i > 0:
            assert obj["id"] == 7
        mesh, scalar, vector = line["chunks"][2:5]
        assert mesh["vertices"] == [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
        assert mesh["indices"] == [[0, 1, 2]]
        assert scalar["dims"] == [4, 3, 2] and scalar["components"] == 1
        assert scalar["shape"] == [2, 3, 4] and scalar["total"] == sum(range(24))
        assert scalar["origin"] == [1, 2, 3] and scalar["spacing"] == 0.5
        assert vector["shape"] == [1, 2, 2, 3] and vector["total"] == 12
        assert vector["dynamic"] is False
        force, user = line["chunks"][5:7]
        assert force["is_force"] and force["force"] == [0, -9.81, 0]
        assert force["point"] == [1, 1, 1] and force["duration"] == 0.01
        assert user["payload"] == [1, 2]


def test_a_16_mib_resource_written_through_a_view_is_read_in_place_downstream(tmp_path, package):
    result = run(tmp_path, chain(tmp_path, package, **{"resource-bytes": MIB16}),
                 "--iterations", "3")
    assert result.code == 0, result.stderr
    lines = [json.loads(x) for x in (tmp_path / "checked.jsonl").read_text().splitlines()]
    for i, line in enumerate(lines):
        raw = line["chunks"][-1]
        assert raw["nbytes"] == MIB16
        assert raw["first"] == i and raw["last"] == MIB16 // 4 - 1 + i and raw["sum_ok"]
        # The view lies inside the received message's bytes: no copy, and it is read-only.
        assert raw["in_place"] and not raw["writeable"]


def test_forwarding_by_reference_sends_the_same_message(tmp_path, package):
    result = run(tmp_path, chain(tmp_path, package), "--iterations", "4")
    assert result.code == 0, result.stderr
    outputs = {(o["module"], o["port"]): o for o in result.report["outputs"]}
    assert outputs[("p", "out")]["last_digest"] == outputs[("f", "out")]["last_digest"]
    assert outputs[("f", "out")]["messages"] == 4


def test_a_python_exception_fails_the_run_naming_the_module_with_its_traceback(tmp_path, package):
    app = application(tmp_path, package, [("p", "producer", {}), ("boom", "raiser", {})],
                      [("p.out", "boom.in")])
    result = run(tmp_path, app, "--iterations", "10")
    assert result.code != 0
    assert result.report["status"] == "failed"
    assert "'boom'" in result.report["error"]
    assert result.module("boom")["exit_code"] == 1
    log = result.log("boom")
    assert "Traceback (most recent call last)" in log
    assert "raiser.py\", line 10" in log and "ZeroDivisionError: division by zero" in log
    assert "ZeroDivisionError: division by zero" in result.stderr
    detail = result.report["error_detail"]
    assert "module 'boom'" in detail and "ZeroDivisionError: division by zero" in detail
    assert "Traceback (most recent call last)" in detail


def test_reading_an_undeclared_parameter_raises_naming_the_module_and_the_parameter(
        tmp_path, package):
    app = application(tmp_path, package, [("p", "producer", {}), ("m", "misreader", {})],
                      [("p.out", "m.in")])
    result = run(tmp_path, app, "--iterations", "3")
    assert result.code != 0
    assert ("vrflow._module.ParameterError: module 'm' (pytest/misreader): reads parameter "
            "'cuont', which is not declared") in result.log("m")


def test_a_parameter_out_of_its_manifest_range_stops_the_run_before_it_starts(tmp_path, package):
    app = application(tmp_path, package, [("p", "producer", {"resource-bytes": 2}),
                                          ("c", "checker", {})], [("p.out", "c.in")])
    result = run(tmp_path, app, "--iterations", "3")
    assert result.code == 2
    assert "resource-bytes" in result.stderr and "'p'" in result.stderr
    assert not (tmp_path / "logs" / "p.log").exists()


def test_a_manifest_naming_a_missing_script_is_refused_naming_the_script(tmp_path, package):
    manifest = package / "vrflow-package.xml"
    manifest.write_text(manifest.read_text().replace('script="checker.py"', 'script="nope.py"'))
    app = application(tmp_path, package, [("p", "producer", {}), ("c", "checker", {})],
                      [("p.out", "c.in")])
    result = run(tmp_path, app, "--iterations", "3")
    assert result.code == 2
    # A long path is cut after its first bytes (vrflow/base/echo.hpp): a short one is whole.
    script = str(package / "nope.py")
    shown = script if len(script) <= 128 else script[:100]
    assert f"module 'c' (pytest/checker): cannot read its script '{shown}" in result.stderr
    assert "' (No such file or directory), resolved from " in result.stderr
    assert "pytest-package/vrflow-package.xml:19 against the manifest's folder" in result.stderr


def test_a_manifest_with_both_executable_and_script_is_refused(tmp_path, package):
    manifest = package / "vrflow-package.xml"
    manifest.write_text(manifest.read_text().replace(
        'script="checker.py"', 'script="checker.py" executable="vrflow"'))
    app = application(tmp_path, package, [("p", "producer", {}), ("c", "checker", {})],
                      [("p.out", "c.in")])
    result = run(tmp_path, app, "--iterations", "3")
    assert result.code == 2
    assert "sets both executable and script" in result.stderr
    assert "vrflow-package.xml:" in result.stderr


def test_a_module_started_outside_a_run_cannot_join_and_says_so():
    script = "import vrflow\nm = vrflow.Module()\nm.add_input('in')\nm.init()\n"
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 1
    assert "vrflow._module.Error" in done.stderr


def test_wait_releases_the_gil_so_python_threads_run_while_a_module_waits(tmp_path, package):
    app = application(tmp_path, package, [("p", "producer", {"period": 0.2}),
                                          ("t", "ticker", {"out": tmp_path / "ticks.txt"})],
                      [("p.out", "t.in")])
    result = run(tmp_path, app, "--iterations", "4")
    assert result.code == 0, result.stderr
    counts = [int(x) for x in (tmp_path / "ticks.txt").read_text().split()]
    assert len(counts) == 4
    # Each wait after the first lasts about the producer's 0.2 s; a thread that sleeps 1 ms per
    # tick counts dozens in it even on a loaded machine, and 0 if wait() held the GIL.
    assert all(c > 3 for c in counts[1:]), counts


def test_a_manifest_with_an_interpreter_but_no_script_is_refused(tmp_path, package):
    manifest = package / "vrflow-package.xml"
    manifest.write_text(manifest.read_text().replace(
        'script="checker.py"', 'executable="vrflow" interpreter="python3"'))
    app = application(tmp_path, package, [("p", "producer", {}), ("c", "checker", {})],
                      [("p.out", "c.in")])
    result = run(tmp_path, app, "--iterations", "3")
    assert result.code == 2
    assert "interpreter is set on 'checker', which has no script" in result.stderr
