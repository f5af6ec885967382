"""validate() gives what `vrflow validate` prints, line for line, for broken applications built
in Python (checked before they are saved, then compared with the program on the saved file) and
for files written by hand."""

import os
import subprocess

import pytest

from conftest import SOURCE_DIR, VRFLOW, vrflow
from vrflow import app


def unknown_names(a):
    a.module("s", "cor/source", count=1)
    a.module("t", "core/sourse")
    a.module("u", "core/source", cont=3)
    a.module("v", "core/source", count="three")
    a.module("w", "core/points", dt=20)


def ports_and_inputs(a):
    src = a.module("src", "core/source")
    a.module("sink", "core/recorder")
    relay = a.module("relay", "core/relay")
    a.connect(src.out, "sink.input")
    a.connect(relay["in"], "sink.in")
    a.module("p", "core/points").input("event", initial_messages=1)


def cycle_without_initial_message(a):
    chain = a.module("chain", "core/points")
    springs = a.module("springs", "core/spring")
    a.connect(chain.objects, springs.objects)
    a.connect(springs.forces, chain.events)


def ids_and_hosts(a):
    a.host("h1")
    a.host("h1")
    a.host("h2", "999.1.1.1")
    a.module("a.b", "core/source")
    a.module("x", "core/source", host="h3")
    a.filter("x", "passthrough")


def more_than_twenty_problems(a):
    for i in range(25):
        a.module(f"sink{i}", "core/recorder")


def warning_only(a):
    src = a.module("src", "core/source")
    sink = a.module("sink", "core/recorder")
    a.connect(src.out, sink.in_)
    a.connect(src.out, sink.in_)
    a.place("ghost", 1, 2)


def problems_inside_composites(a):
    def broken(scope):
        scope.module("r", "core/relay", delay_ms=-1)
        return {}

    a.add(broken, "py")
    name = a.define(os.path.join(SOURCE_DIR, "examples/composite_workers/chain.vrc.xml"))
    a.instance("xml", name, count="many")
    a.instance("ghost", "no_such_composite")


def output_folder_missing(a):
    src = a.module("src", "core/source")
    sink = a.module("sink", "core/recorder", file="/nonexistent-vrflow-62/out.csv")
    a.connect(src.out, sink.in_)


BROKEN = [unknown_names, ports_and_inputs, cycle_without_initial_message, ids_and_hosts,
          more_than_twenty_problems, warning_only, problems_inside_composites,
          output_folder_missing]


@pytest.mark.parametrize("make", BROKEN, ids=[make.__name__ for make in BROKEN])
def test_validate_prints_what_vrflow_validate_prints(make, tmp_path):
    path = str(tmp_path / f"{make.__name__}.xml")
    a = app.Application(make.__name__, path)
    make(a)
    before_saving = a.validate()
    assert not os.path.exists(path)
    a.save()
    status, printed = vrflow("validate", path)
    assert before_saving.text == printed
    assert a.validate().text == printed
    assert before_saving.ok == (status == 0)
    assert printed  # every case has something to say


def test_a_hand_written_file_is_checked_at_its_own_lines(tmp_path):
    path = tmp_path / "hand.xml"
    path.write_text('<?xml version="1.0"?>\n<application   name="hand">\n\n\n  <modules>\n'
                    '    <module type="relay"  package="core" id="r"/>\n'
                    '    <module id="s" package="core" type="sourse"/>\n'
                    '  </modules>\n</application>\n')
    status, printed = vrflow("validate", str(path))
    validation = app.load(path).validate()
    assert status == 1
    assert validation.text == printed
    assert validation.errors[0].line == 6
    assert [d.line for d in validation.diagnostics] == [6, 7]


def test_check_raises_with_the_diagnostics(tmp_path):
    a = app.Application("broken", str(tmp_path / "broken.xml"))
    cycle_without_initial_message(a)
    with pytest.raises(app.ValidationError) as raised:
        a.check()
    assert len(raised.value.diagnostics) == 1
    problem = raised.value.diagnostics[0]
    assert (problem.severity, problem.line, problem.column) == ("error", 8, 5)
    assert problem.message.startswith("cycle without initial message (would deadlock): "
                                      "chain.objects -> springs.objects")
    assert str(raised.value) == str(problem)


def test_a_valid_application_passes_with_its_warnings():
    a = app.Application("fine")
    warning_only(a)
    validation = a.check()
    assert validation.ok
    assert [d.severity for d in validation.diagnostics] == ["warning", "warning"]


def test_packages_that_cannot_be_loaded_are_the_error_vrflow_prints(tmp_path):
    folder = tmp_path / "pkgs" / "bad"
    folder.mkdir(parents=True)
    (folder / "vrflow-package.xml").write_text("<package name='bad'>\n<module>\n</package>\n")
    path = str(tmp_path / "app.xml")
    a = app.Application("pkgs", path)
    a.module("s", "core/source")
    validation = a.validate(packages=[tmp_path / "pkgs"])
    a.save()
    status, printed = vrflow("validate", "--packages", str(tmp_path / "pkgs"), path)
    assert (status, validation.text) == (2, printed)
    assert validation.catalog_failed and not validation.ok


def test_set_and_package_folders_of_the_file_are_taken_as_vrflow_takes_them(tmp_path):
    path = str(tmp_path / "app.xml")
    a = app.Application("set", path)
    a.packages("missing-folder")
    src = a.module("src", "core/source")
    sink = a.module("sink", "core/recorder")
    a.connect(src.out, sink.in_)
    validation = a.validate(set={"src.count": -4})
    a.save()
    status, printed = vrflow("validate", "--set", "src.count=-4", path)
    assert (status, validation.text) == (1, printed)
    assert "missing-folder" in printed and "below its minimum" in printed


def test_expand_gives_the_flat_application_vrflow_expand_prints(tmp_path):
    path = str(tmp_path / "composite.xml")
    a = app.Application("expand", path)
    name = a.define(os.path.join(SOURCE_DIR, "examples/composite_workers/chain.vrc.xml"))
    a.instance("c0", name)
    a.instance("c1", name)
    flat = a.expand()
    assert len(flat.model.instances) == 0
    assert {m.id.split(":")[0] for m in flat.model.modules} == {"c0", "c1"}
    a.save()
    printed = subprocess.run([VRFLOW, "expand", path], capture_output=True, text=True,
                             check=True).stdout
    assert flat.text() == printed
    broken = app.Application("broken", str(tmp_path / "broken.xml"))
    broken.instance("ghost", "no_such_composite")
    with pytest.raises(app.ValidationError, match="no_such_composite"):
        broken.expand()
