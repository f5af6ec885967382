"""Reads a parameter its manifest does not declare (a typo)."""

import vrflow

module = vrflow.Module()
inp = module.add_input("in")
module.init()
print(module.params["cuont"])
