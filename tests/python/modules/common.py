"""What the test modules share: the object type they write, with every parameter kind."""

import vrflow

KINDS = [("s", "scalar"), ("v", "vec3"), ("q", "quat"), ("m", "mat3"), ("box", "aabb"),
         ("ref", "id"), ("n", "int64"), ("f", "float_array"), ("d", "double_array"),
         ("b", "bytes")]
vrflow.register_type("pytest-all", KINDS)
