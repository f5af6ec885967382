"""Counts in a Python thread while the main thread blocks in wait(): the count advances during a
wait only if wait() releases the GIL."""

import threading
import time

import vrflow

ticks = 0
running = True


def tick():
    global ticks
    while running:
        ticks += 1
        time.sleep(0.001)


module = vrflow.Module()
inp = module.add_input("in")
module.init()
thread = threading.Thread(target=tick)
thread.start()
seen = []
while True:
    before = ticks
    if not module.wait():
        break
    seen.append(ticks - before)
running = False
thread.join()
with open(module.params["out"], "w", encoding="utf-8") as out:
    out.write("\n".join(map(str, seen)) + "\n")
