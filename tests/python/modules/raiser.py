"""Fails on its third iteration with a Python exception."""

import vrflow

module = vrflow.Module()
inp = module.add_input("in")
module.init()
while module.wait():
    if module.iteration == 2:
        print(1 / 0)
