"""Gathers the workers' primes and shows the progress, FlowVR's primes visu in Python."""

import numpy as np

import vrflow

module = vrflow.Module()
inp = module.add_input("primes")
module.init()
out = module.params["out"]
held = []
while module.wait():
    message = module.get(inp)
    for chunk in message:
        resource = chunk.as_resource()
        if resource is not None:
            held.append(resource.data.view(np.uint64).copy())  # kept past this iteration
    count = sum(len(p) for p in held)
    largest = max((int(p.max()) for p in held if len(p)), default=0)
    stamps = message.stamps
    print(f"iteration {module.iteration}: {count} primes, largest {largest}, "
          f"{stamps['found']} new, {stamps['computationTimeIt']:.4f} s of compute")
module.close()
every = np.sort(np.concatenate(held)) if held else np.empty(0, dtype=np.uint64)
np.savetxt(out, every, fmt="%d")
