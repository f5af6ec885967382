"""A primes worker: tests its share of the integers with a NumPy sieve, block after block."""

import time

import numpy as np

import vrflow


def primes_in(low, high):
    """The primes in [low, high): a segmented sieve of Eratosthenes."""
    if high <= 2:
        return np.empty(0, dtype=np.uint64)
    limit = int(high ** 0.5) + 1
    small = np.ones(limit + 1, dtype=bool)
    small[:2] = False
    for p in range(2, int(limit ** 0.5) + 1):
        if small[p]:
            small[p * p::p] = False
    candidates = np.ones(high - low, dtype=bool)
    for p in np.flatnonzero(small):
        first = max(p * p, (low + p - 1) // p * p)
        candidates[first - low::p] = False
    found = np.flatnonzero(candidates).astype(np.uint64) + np.uint64(low)
    return found[found >= 2]


module = vrflow.Module()
out = module.add_output("primes")
module.init()
index, workers, block = (module.params[k] for k in ("index", "workers", "block"))
while module.wait():
    start = time.perf_counter()
    b = module.iteration * workers + index
    found = primes_in(b * block, (b + 1) * block)
    message = module.new_message(size_hint=found.nbytes + 512)
    message.add_stamp("computationTimeIt", time.perf_counter() - start)
    message.add_stamp("found", len(found))
    # Written straight into the message in shared memory (no copy of the array's bytes later).
    message.new_raw_resource(b, found.nbytes).view(np.uint64)[:] = found
    module.put(out, message)
