#!/usr/bin/env python3
"""examples/pipeline/pipeline.xml written with vrflow's Python builder (docs/python-apps.md).

    PYTHONPATH=build/python python3 examples/pipeline/pipeline.py [OUT.xml]

writes the canonical form of pipeline.xml (what the editor saves) to OUT.xml, or prints it;
`--validate` checks it as `vrflow validate` does, `--run N` runs it N iterations and prints the
report (app.main)."""

from vrflow import app


def build():
    """The pipeline: a chain of points, its springs and gravity, a relay and a recorder."""
    a = app.Application("pipeline")
    local = a.host("local")
    chain = a.module("chain", "core/points", local, count=8, dt=0.005)
    chain.input("events", initial_messages=1)
    springs = a.module("springs", "core/spring", local, stiffness=400, damping=0.8)
    gravity = a.module("gravity", "core/gravity", local)
    relay = a.module("relay", "core/relay", local)
    recorder = a.module("recorder", "core/recorder", local, file="out/demo/trajectory.csv")
    a.connect(chain.objects, springs.objects)
    a.connect(chain.objects, gravity.objects)
    a.connect(springs.forces, chain.events)
    a.connect(gravity.forces, chain.events)
    a.connect(chain.objects, relay.in_)
    a.connect(relay.out, recorder.in_)
    for node, x, y in [(chain, 0, 0), (springs, 240, -80), (gravity, 240, 80), (relay, 240, 200),
                       (recorder, 480, 200)]:
        a.place(node, x, y)
    return a


if __name__ == "__main__":
    app.main(build)
