"""The Python pass-through of vrflow-bench-python: forwards each message by reference."""

import vrflow

with vrflow.Module() as module:
    inp = module.add_input("in")
    out = module.add_output("out")
    module.init()
    wait, get, put = module.wait, module.get, module.put
    while wait():
        put(out, get(inp))
