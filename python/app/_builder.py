"""Nodes, ports and the scopes that add them: what `Application` and Python composites share."""

import math

from . import _app


def param_text(value):
    """A parameter's value as the text the file holds: bools `true`/`false`, numbers in their
    shortest form (`400`, `0.005`), sequences (a vec3) joined by spaces, anything else str()."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"parameter value {value!r} is not a finite number")
        if value.is_integer() and abs(value) < 1e15:
            return str(int(value))
        return repr(value)
    if isinstance(value, (list, tuple)):
        return " ".join(param_text(item) for item in value)
    return str(value)


def set_params(params, values, keywords):
    """Sets `values` (exact names) then `keywords` (a Python name, `_` read as `-`: `state_file`
    sets `state-file`) on a ParamList, in order."""
    for name, value in (values or {}).items():
        params.set(name, param_text(value))
    for name, value in keywords.items():
        params.set(name.replace("_", "-"), param_text(value))


def comment_list(comment):
    """`comment=` of a builder call: None, one text or a list of texts, each written as
    `<!--text-->` just before the element."""
    if comment is None:
        return []
    return [comment] if isinstance(comment, str) else list(comment)


class Port:
    """One port of a node, written `node.port` in connections."""

    def __init__(self, node, name):
        self.node = node
        self.name = name

    def __str__(self):
        return f"{self.node}.{self.name}"

    def __repr__(self):
        return f"Port({str(self)!r})"


def endpoint(port):
    """The model's endpoint of a Port or of `node.port` text."""
    text = str(port)
    node, dot, name = text.partition(".")
    if not dot:
        raise ValueError(f"endpoint '{text}' must be written node.port (or be a Port)")
    return _app.Endpoint(node, name)


class Node:
    """A module, filter or composite instance added to an application: `node.out` or
    `node["in"]` is a port (a trailing `_` is dropped, for Python's keywords: `node.in_`)."""

    def __init__(self, node_id):
        self.id = node_id

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return Port(self.id, name[:-1] if name.endswith("_") else name)

    def __getitem__(self, name):
        return Port(self.id, name)

    def __str__(self):
        return self.id

    def __repr__(self):
        return f"{type(self).__name__}({self.id!r})"


class ModuleNode(Node):
    """A module of the application; `input()` configures the input filter of one of its ports."""

    def __init__(self, model, index):
        super().__init__(model.modules[index].id)
        self._model = model
        self._index = index

    def input(self, port, initial_messages=0, mode="fifo", comment=None):
        """Sets `<input port=... initial-messages=... mode=...>` of input `port`; returns self."""
        config = _app.InputConfig()
        config.port = port
        config.initial_messages = initial_messages
        config.mode = mode
        config.comments = comment_list(comment)
        self._model.modules[self._index].inputs.append(config)
        return self


class Ports:
    """The ports a Python composite exposes: `w.out` or `w["in"]` as for a node."""

    def __init__(self, name, ports):
        self.id = name
        self._ports = dict(ports)

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        return self[name[:-1] if name.endswith("_") else name]

    def __getitem__(self, name):
        if name not in self._ports:
            known = ", ".join(sorted(self._ports)) or "none"
            raise KeyError(f"composite instance '{self.id}' exposes no port '{name}' "
                           f"(its ports: {known})")
        return self._ports[name]

    def __iter__(self):
        return iter(self._ports)


class Scope:
    """Adds nodes and connections to an application model. The application is the outermost
    scope; a Python composite gets a scope whose ids are prefixed by `instance:` (as
    expandComposites() names what an XML composite makes) and whose nodes run on its host."""

    def __init__(self, model, prefix="", host=None):
        self._model = model
        self._prefix = prefix
        self._host = host

    def _id(self, node_id):
        return self._prefix + node_id

    def _host_id(self, host):
        host = host if host is not None else self._host
        return "" if host is None else str(host)

    def module(self, node_id, module_type, host=None, *, endit=None, params=None, comment=None,
               **values):
        """Adds module `node_id` of `module_type` ("package/type"), its parameters given as
        keywords (`count=10`, `state_file="x.json"` for `state-file`) or in `params`."""
        package, slash, type_name = module_type.partition("/")
        if not slash or not package or not type_name:
            raise ValueError(f"module type '{module_type}' must be written package/type")
        module = _app.Module()
        module.id = self._id(node_id)
        module.package = package
        module.type = type_name
        module.host = self._host_id(host)
        if endit is not None:
            module.endit = endit
        set_params(module.params, params, values)
        module.comments = comment_list(comment)
        self._model.modules.append(module)
        return ModuleNode(self._model, len(self._model.modules) - 1)

    def filter(self, node_id, filter_type, host=None, *, plugin=None, params=None, comment=None,
               **values):
        """Adds filter `node_id` of `filter_type` (built-in or from `plugin`), its parameters as
        for module()."""
        node = _app.Filter()
        node.id = self._id(node_id)
        node.type = filter_type
        node.host = self._host_id(host)
        node.plugin = plugin or ""
        set_params(node.params, params, values)
        node.comments = comment_list(comment)
        self._model.filters.append(node)
        return Node(node.id)

    def instance(self, node_id, composite, host=None, *, params=None, comment=None, **values):
        """Adds an instance of the XML composite `composite` (defined in the file, or found as
        NAME.vrc.xml: docs/composites.md); its exposed ports are `node.port` as for a node."""
        node = _app.Instance()
        node.id = self._id(node_id)
        node.composite = composite
        node.host = self._host_id(host)
        set_params(node.params, params, values)
        node.comments = comment_list(comment)
        self._model.instances.append(node)
        return Node(node.id)

    def add(self, composite, node_id, host=None, **arguments):
        """Adds the Python composite `composite` as instance `node_id`: calls
        `composite(scope, **arguments)`, where `scope` adds nodes named `node_id:...`, and returns
        the ports it exposes (the dict it returned) as Ports."""
        inner = Scope(self._model, self._id(node_id) + ":",
                      host if host is not None else self._host)
        exposed = composite(inner, **arguments)
        return Ports(self._id(node_id), exposed or {})

    def connect(self, source, target, capacity=0, policy="block", comment=None):
        """Connects output `source` to input `target` (Ports, or `node.port` text)."""
        connection = _app.Connection()
        connection.source = endpoint(source)
        connection.target = endpoint(target)
        connection.capacity = capacity
        connection.policy = policy
        connection.comments = comment_list(comment)
        self._model.connections.append(connection)

    def place(self, node, x, y, comment=None):
        """Where the editor draws `node` (a Node or its id)."""
        position = _app.EditorNode(str(node), float(x), float(y))
        position.comments = comment_list(comment)
        self._model.editor.append(position)
