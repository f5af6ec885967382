"""A wind force field computed with NumPy: drag towards a gusting wind, on rigid bodies and on
every node of mass-spring nets (examples/python_wind/README.md).

The wind's velocity at point x and time t is
    w(x, t) = velocity * (1 + gust * sin(2 pi frequency t - k . x)),  k = 2 pi velocity / |velocity|^2 * frequency
(a gust travelling downwind at the wind's speed). A body or node moving at v feels the linear
drag F = drag * (w(x, t) - v) (N), applied for the step.
"""

import numpy as np

import vrflow

NODE_FORCES = 1025  # the massspring package's node-forces event (nodes/massspring/events.hpp)
RECORD = np.dtype([("node", "<u4"), ("pad", "<u4"), ("force", "<f8", 3)])

module = vrflow.Module()
objects = module.add_input("objects")
forces = module.add_output("forces")
module.init()
params = module.params
velocity = np.array(params["velocity"], dtype=float)
gust, frequency = params["gust"], params["frequency"]
drag, node_drag = params["drag"], params["node-drag"]
speed2 = float(velocity @ velocity)
wavevector = 2 * np.pi * frequency * velocity / speed2 if speed2 > 0 else np.zeros(3)

bodies = {}  # id -> [position, velocity] of each rigid body
nets = {}    # id -> {"positions": (n, 3), "velocities": (n, 3), "pinned": (n,)}


def wind_at(points, t):
    """The wind's velocity at each row of `points` (n, 3)."""
    phase = 2 * np.pi * frequency * t - points @ wavevector
    return velocity * (1 + gust * np.sin(phase))[:, None]


def remember(obj):
    """Keeps the scene: add and update chunks carry the parameters that changed."""
    if obj.op == "delete":
        bodies.pop(obj.id, None)
        nets.pop(obj.id, None)
    elif obj.type == "rigid":
        state = bodies.setdefault(obj.id, [np.zeros(3), np.zeros(3)])
        if obj.has("position"):
            state[0] = np.array(obj["position"])
        if obj.has("linearVelocity"):
            state[1] = np.array(obj["linearVelocity"])
    elif obj.type == "massspring":
        net = nets.setdefault(obj.id, {})
        for key in ("positions", "velocities"):
            if obj.has(key):
                net[key] = np.array(obj[key]).reshape(-1, 3)  # a copy: the message goes away
        if obj.has("pinned"):
            net["pinned"] = np.array(obj["pinned"], dtype=bool)


while module.wait():
    for chunk in module.get(objects):
        obj = chunk.as_object()
        if obj is not None:
            remember(obj)
    t, dt = module.sim_time, module.time_step or 0.01
    out = module.new_message()
    if bodies:
        ids = list(bodies)
        x = np.array([bodies[i][0] for i in ids])
        v = np.array([bodies[i][1] for i in ids])
        f = drag * (wind_at(x, t) - v)
        for body, force, point in zip(ids, f, x):
            out.add_force(body, force=force, point=point, duration=dt)
    for net_id, net in nets.items():
        if "positions" not in net:
            continue
        x = net["positions"]
        v = net.get("velocities", np.zeros_like(x))
        records = np.zeros(len(x), dtype=RECORD)
        records["node"] = np.arange(len(x))
        records["force"] = node_drag * (wind_at(x, t) - v)
        header = np.array([len(x), 0], dtype="<u4")
        out.add_event(net_id, NODE_FORCES, header.tobytes() + records.tobytes())
    module.put(forces, out)
