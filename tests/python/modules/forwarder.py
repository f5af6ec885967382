"""Forwards what it receives by reference (no copy)."""

import vrflow

with vrflow.Module() as module:
    inp = module.add_input("in")
    out = module.add_output("out")
    module.init()
    while module.wait():
        module.put(out, module.get(inp))
