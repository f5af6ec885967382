"""The builder makes vrflow's own model: what it saves is the canonical XML, byte for byte as
written by hand below, and loading it gives it back."""

import os

import pytest

from vrflow import app

# Written by hand, in the canonical form of docs/application-format.md.
EXPECTED = """<?xml version="1.0" encoding="UTF-8"?>
<!-- built in Python -->
<application name="demo" version="1">
  <packages path="pkgs"/>
  <hosts>
    <host id="a"/>
    <host id="b" address="127.0.62.2"/>
  </hosts>
  <modules>
    <module id="src" package="core" type="source">
      <param name="count" value="10"/>
      <param name="size" value="4096"/>
    </module>
    <!-- the animator -->
    <module id="chain" package="core" type="points" host="b" endit="after-wait">
      <param name="dt" value="0.005"/>
      <param name="spacing" value="1e-07"/>
      <input port="events" initial-messages="1" mode="latest"/>
    </module>
    <module id="w0:r1" package="core" type="relay"/>
    <module id="w0:r2" package="core" type="relay">
      <param name="delay-ms" value="2"/>
    </module>
    <module id="sink" package="core" type="recorder">
      <param name="file" value="out/a b&amp;c.csv"/>
    </module>
  </modules>
  <instances>
    <instance id="pair" composite="relay_pair" host="b">
      <param name="n" value="3"/>
    </instance>
  </instances>
  <filters>
    <filter id="m" type="merge">
      <param name="inputs" value="2"/>
    </filter>
    <filter id="g" type="decimate" host="b">
      <param name="count" value="10"/>
    </filter>
  </filters>
  <connections>
    <connection from="w0:r1.out" to="w0:r2.in" capacity="4" policy="drop-oldest"/>
    <connection from="src.out" to="w0:r1.in"/>
    <connection from="w0:r2.out" to="m.in0"/>
    <connection from="pair.out" to="m.in1"/>
    <!-- into the recorder -->
    <connection from="m.out" to="sink.in"/>
  </connections>
  <editor>
    <node ref="src" x="10" y="-20.5"/>
    <note id="why" y="100">two lines
of text</note>
    <frame id="f" title="Relays" width="300" height="200" color="#3366cc"/>
  </editor>
</application>
"""


def relay_pair(scope, delay_ms=0):
    """A Python composite: two relays in a row; exposes their ends."""
    first = scope.module("r1", "core/relay")
    second = scope.module("r2", "core/relay", delay_ms=delay_ms)
    scope.connect(first.out, second["in"], capacity=4, policy="drop-oldest")
    return {"in": first["in"], "out": second.out}


def build():
    a = app.Application("demo", comment=" built in Python ")
    a.packages("pkgs")
    first = a.host("a")
    second = a.host("b", "127.0.62.2")
    src = a.module("src", "core/source", first, count=10, size=4096)
    a.module("chain", "core/points", second, endit="after-wait", dt=0.005, spacing=1e-7,
             comment=" the animator ").input("events", initial_messages=1, mode="latest")
    pair = a.add(relay_pair, "w0", delay_ms=2)
    sink = a.module("sink", "core/recorder", params={"file": "out/a b&c.csv"})
    xml_pair = a.instance("pair", "relay_pair", second, n=3)
    merge = a.filter("m", "merge", inputs=2)
    a.filter("g", "decimate", second, count=10)
    a.connect(src.out, pair.in_)
    a.connect(pair.out, merge.in0)
    a.connect(xml_pair.out, "m.in1")
    a.connect(merge.out, sink["in"], comment=" into the recorder ")
    a.place(src, 10, -20.5)
    a.note("why", "two lines\nof text", y=100)
    a.frame("f", "Relays", width=300, height=200, color="#3366cc")
    return a


def test_saved_xml_equals_the_hand_written_canonical_file(tmp_path):
    a = build()
    assert a.text() == EXPECTED
    path = a.save(tmp_path / "demo.xml")
    assert a.path == str(tmp_path / "demo.xml")
    assert open(path, encoding="utf-8").read() == EXPECTED


def test_loading_the_saved_file_gives_the_same_model_and_bytes(tmp_path):
    path = build().save(tmp_path / "demo.xml")
    loaded = app.load(path)
    assert loaded.path == path
    assert loaded.text() == EXPECTED
    assert [m.id for m in loaded.model.modules] == ["src", "chain", "w0:r1", "w0:r2", "sink"]
    chain = loaded.model.modules[1]
    assert (chain.host, chain.endit) == ("b", "after-wait")
    assert chain.params.find("spacing") == "1e-07"
    assert (chain.inputs[0].port, chain.inputs[0].initial_messages) == ("events", 1)
    assert loaded.model.modules[0].host == "a"  # the loader gives the first host back
    assert loaded.model.modules[0].loc.line == 10


def test_a_loaded_application_is_changed_and_saved_again(tmp_path):
    path = build().save(tmp_path / "demo.xml")
    loaded = app.load(path)
    loaded.model.modules[0].params.set("count", "20")
    loaded.connect("src.out", "sink.in", policy="drop-newest")
    loaded.save()
    again = app.load(path).text()
    assert '<param name="count" value="20"/>' in again
    assert '<connection from="src.out" to="sink.in" policy="drop-newest"/>' in again


def test_parameter_values_are_written_as_the_file_holds_them():
    assert app.param_text(True) == "true"
    assert app.param_text(400.0) == "400"
    assert app.param_text(0.1) == "0.1"
    assert app.param_text([1.25, 0.95, 0]) == "1.25 0.95 0"
    with pytest.raises(ValueError, match="not a finite number"):
        app.param_text(float("nan"))


def test_bad_builder_calls_are_errors_naming_the_value():
    a = app.Application("bad")
    with pytest.raises(ValueError, match="module type 'source' must be written package/type"):
        a.module("s", "source")
    with pytest.raises(ValueError, match="endpoint 'sink' must be written node.port"):
        a.connect("src.out", "sink")
    with pytest.raises(ValueError, match="policy must be one of block, drop-oldest, drop-newest, "
                                         "got 'drop'"):
        a.connect("src.out", "sink.in", policy="drop")
    with pytest.raises(ValueError, match="endit must be one of after-iteration, after-wait"):
        a.module("s", "core/source", endit="later")
    with pytest.raises(ValueError, match="mode must be one of fifo, latest, got 'newest'"):
        a.module("p", "core/points").input("events", mode="newest")
    with pytest.raises(KeyError, match="exposes no port 'output' \\(its ports: in, out\\)"):
        _ = a.add(relay_pair, "w").output
    with pytest.raises(ValueError, match="save\\(\\) needs a path"):
        a.save()


def test_loading_a_bad_file_is_one_error_naming_it(tmp_path):
    missing = tmp_path / "missing.xml"
    with pytest.raises(app.LoadError, match=str(missing)):
        app.load(missing)
    broken = tmp_path / "broken.xml"
    broken.write_text('<application name="x">\n  <modules>\n</application>\n')
    with pytest.raises(app.LoadError, match=f"{broken}:3:3: error: "):
        app.load(broken)
    unknown = tmp_path / "unknown.xml"
    unknown.write_text('<application>\n  <modules>\n    <module id="a" pakage="core"/>\n'
                       '  </modules>\n</application>\n')
    with pytest.raises(app.LoadError, match=f"{unknown}:3:20: error: unknown attribute 'pakage'"):
        app.load(unknown)
    with pytest.raises(app.LoadError, match="it is a directory, not a regular file"):
        app.load(tmp_path)
    with pytest.raises(app.LoadError, match="not a regular file"):
        app.load_composite("/dev/zero")


def test_saving_into_a_missing_folder_is_an_error_naming_it(tmp_path):
    target = tmp_path / "no" / "demo.xml"
    with pytest.raises(app.VrflowError, match=str(tmp_path / "no")):
        build().save(target)
    assert not os.path.exists(tmp_path / "no")


def test_a_composite_file_is_copied_into_the_application(tmp_path):
    composite = os.path.join(os.environ["VRFLOW_SOURCE_DIR"],
                             "examples/composite_workers/chain.vrc.xml")
    a = app.Application("with composite")
    name = a.define(composite)
    assert name == app.load_composite(composite).name
    a.instance("c0", name)
    text = a.text()
    assert f'<composite name="{name}"' in text
    assert f'<instance id="c0" composite="{name}"/>' in text
    assert app.load(a.save(tmp_path / "c.xml")).text() == text
