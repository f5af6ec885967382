"""Sends every chunk kind; the raw resource is written in place through a NumPy view."""

import time

import numpy as np

import common  # noqa: F401  (registers the object type)
import vrflow

module = vrflow.Module()
out = module.add_output("out")
module.init()
params = module.params
size = params["resource-bytes"]
scale = params["scale"]
period = params["period"]
while module.wait():
    time.sleep(period)
    i = module.iteration
    message = module.new_message(size_hint=size + 4096)
    message.add_stamp("label", params["label"])
    message.add_stamp("flag", params["flag"])
    message.add_stamp("offset-y", float(params["offset"][1]))
    message.set_sim_time(0.25 * i)
    obj = message.add_object(module.new_id() if i == 0 else 7, "pytest-all", op="add")
    obj.set("s", scale * i).set("v", (1.0, 2.0, 3.0)).set("q", (0, 0, 0, 1))
    obj.set("m", np.eye(3)).set("box", ((-1, -2, -3), (1, 2, 3)))
    obj["ref"] = 42
    obj["n"] = -5
    obj["f"] = np.arange(4, dtype=np.float32) * scale
    obj["d"] = np.array([0.5, 0.25])
    obj["b"] = b"abc"
    message.add_delete(9, "pytest-all")
    message.add_mesh(100, np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32),
                     np.array([[0, 1, 2]], dtype=np.uint32))
    message.add_field(101, np.arange(24, dtype=np.float32).reshape(2, 3, 4),
                      origin=(1, 2, 3), spacing=0.5)
    message.add_field(102, np.ones((1, 2, 2, 3), dtype=np.float32), dynamic=False)
    message.add_force(7, force=(0, -9.81, 0), point=(1, 1, 1), duration=0.01)
    message.add_event(7, 1100, b"\x01\x02")
    view = message.new_raw_resource(200, size)  # last: written in place, in shared memory
    words = view.view(np.uint32)
    words[:] = np.arange(words.size, dtype=np.uint32) + i
    module.put(out, message)
