"""vrflow for Python: write modules (docs/python.md).

A module declares its ports, joins the run, then loops::

    import vrflow

    module = vrflow.Module()
    objects = module.add_input("objects")
    forces = module.add_output("forces")
    module.init()
    k = module.params["stiffness"]
    while module.wait():
        out = module.new_message()
        for chunk in module.get(objects):
            ...
        module.put(forces, out)

Received messages are read in place: NumPy arrays view the host's shared memory (read-only);
``OutgoingMessage.new_raw_resource()`` gives a writable view of a new resource.
"""

from collections.abc import Mapping

from vrflow import _module
from vrflow._module import (  # noqa: F401  (the public API)
    Chunk,
    Error,
    EventView,
    Force,
    InputPort,
    Message,
    ObjectView,
    ObjectWriter,
    OutgoingMessage,
    OutputPort,
    ParameterError,
    ResourceView,
    register_type,
)

__all__ = [
    "Chunk", "Error", "EventView", "Force", "InputPort", "Message", "Module", "ObjectView",
    "ObjectWriter", "OutgoingMessage", "OutputPort", "ParameterError", "Parameters",
    "ResourceView", "register_type",
]


class Parameters(Mapping):
    """The module's typed parameters: the application's values over the manifest's defaults.

    ``params["name"]`` is an int, float, bool, str or a 3-tuple, of the type the manifest
    declares; a name the manifest does not declare (or declares without a default, unset)
    raises ParameterError naming the module and the parameter.
    """

    def __init__(self, module):
        self._module = module
        self._values = module._params()

    def __getitem__(self, name):
        if name in self._values:
            return self._values[name]
        return self._module._param(name)  # raises ParameterError with the runtime's message

    def __iter__(self):
        return iter(self._values)

    def __len__(self):
        return len(self._values)


class Module(_module.Module):
    """One module process: ``add_input``/``add_output``, ``init()``, then loop on ``wait()``.

    ``close()`` (or the end of a ``with`` block, or the interpreter's exit) leaves the loop: the
    iteration in progress counts, as when a C++ module's ``Module`` is destroyed.
    """

    @property
    def params(self):
        return Parameters(self)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False
