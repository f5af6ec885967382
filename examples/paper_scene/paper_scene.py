#!/usr/bin/env python3
"""examples/paper_scene/paper_scene.xml written with vrflow's Python builder (docs/python-apps.md).

    PYTHONPATH=build/python python3 examples/paper_scene/paper_scene.py [OUT.xml]

writes the canonical form of paper_scene.xml (what the editor saves, comments kept) to OUT.xml,
or prints it; `--validate` checks it, `--run N` runs it (app.main). Saved beside scene.json, the
file finds the scene as paper_scene.xml does."""

from vrflow import app

GRAVITY = (0, -9.81, 0)


def build():
    """The paper's scene without the fluid: rigid bodies, a mass-spring net and a viewer."""
    a = app.Application("paper-scene", comment=(
        " The paper's scene without the fluid (figures 4 and 5 of Allard & Raffin 2006): 20 rigid\n"
        "     objects of mixed shapes and a 20 x 20 mass-spring net pinned at its corners.\n"
        "     vrflow run examples/paper_scene/paper_scene.xml -n 300 "))
    local = a.host("local")
    bodies = a.module("bodies", "rigid/animator", local, scene="scene.json", dt=0.01,
                      state_file="bodies-final.json").input("events", initial_messages=1)
    contacts = a.module("contacts", "rigid/interactor", local, gravity=GRAVITY)
    field = a.module("field", "rigid/forcefield", local, field="gravity 0 -9.81 0")
    net = a.module("net", "massspring/animator", local, n=20, m=20, spacing=0.1, mass=8,
                   stiffness=300, damping=0.2, origin=(1.25, 0.95, 0), dt=0.01, substeps=3,
                   internal_springs=True, gravity=GRAVITY, state_file="net-final.txt", comment=(
                       " The net integrates its own springs (internal-springs) in 3 sub-steps of"
                       " 3.3 ms: its\n         fastest mode has omega h = 1.0 there; applied once"
                       " per 10 ms step (the paper's separate\n         spring interactor) omega"
                       " dt = 3.0 is beyond the explicit limit of 2 and it blows up. ")
                   ).input("events", initial_messages=1)
    collisions = a.module("net-collisions", "massspring/collision", local, comment=(
        " Net collisions are a smooth interaction: one initial message lets them run beside the\n"
        "         animators on states one iteration old (section 4.2 of the paper). Rigid"
        " contacts and\n"
        "         rigid/net contacts stay sequential with their animators: rigid/net\n"
        "         contact is solved with the net's nodes on the current state, which is what"
        " keeps a\n"
        "         heavy or fast object from passing through the net (issue 26). "
        )).input("objects", initial_messages=1)
    net_contacts = a.module("net-contacts", "massspring/rigid", local)
    camera = a.module("camera", "viewer/viewer", local, output_dir=".", prefix="demo",
                      eye=(1.2, 3.2, 6.2), target=(0, 0.4, 0))

    objects = [(bodies, field), (bodies, contacts), (bodies, net_contacts), (net, net_contacts),
               (net, collisions), (bodies, camera), (net, camera)]
    for i, (source, target) in enumerate(objects):
        a.connect(source.objects, target.objects, comment=None if i else (
            " Objects: every animator to the interactors that handle their type, and to the"
            " viewer. "))
    forces = [(field, bodies), (contacts, bodies), (net_contacts, bodies), (collisions, net),
              (net_contacts, net)]
    for i, (source, target) in enumerate(forces):
        a.connect(source.forces, target.events, comment=None if i else (
            " Forces: only to the animators that own the objects (figure 5's pruned network). "))
    return a


if __name__ == "__main__":
    app.main(build)
