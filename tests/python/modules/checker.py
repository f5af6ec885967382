"""Reads every chunk of what it receives and writes one JSON line per message."""

import json

import numpy as np

import common  # noqa: F401  (registers the object type)
import vrflow


def plain(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, tuple):
        return [plain(v) for v in value]
    return value


module = vrflow.Module()
inp = module.add_input("in")
module.init()
with open(module.params["out"], "w", encoding="utf-8") as lines:
    while module.wait():
        message = module.get(inp)
        whole = message.bytes
        start = whole.__array_interface__["data"][0]
        end = start + whole.nbytes
        line = {"iteration": module.iteration, "source": message.source,
                "sim_time": module.sim_time, "stamps": message.stamps, "chunks": []}
        for chunk in message:
            entry = {"kind": chunk.kind, "id": chunk.id}
            if (obj := chunk.as_object()) is not None:
                entry.update(op=obj.op, type=obj.type,
                             params={k: plain(v) for k, v in obj.params().items()})
            elif (res := chunk.as_resource()) is not None:
                entry.update(resource=res.kind, dynamic=res.dynamic)
                if res.kind == "raw":
                    words = res.data.view(np.uint32)
                    address = res.data.__array_interface__["data"][0]
                    entry.update(nbytes=res.data.nbytes, first=int(words[0]),
                                 last=int(words[-1]),
                                 in_place=bool(start <= address < end and not res.data.flags.owndata),
                                 writeable=bool(res.data.flags.writeable),
                                 sum_ok=bool((words == np.arange(words.size, dtype=np.uint32)
                                              + words[0]).all()))
                elif res.kind == "mesh":
                    mesh = res.mesh()
                    entry.update(vertices=plain(mesh["vertices"]), indices=plain(mesh["indices"]))
                else:
                    field = res.field()
                    entry.update(dims=list(field["dims"]), components=field["components"],
                                 origin=list(field["origin"]), spacing=field["spacing"],
                                 shape=list(field["data"].shape),
                                 total=float(field["data"].sum()))
            elif (event := chunk.as_event()) is not None:
                entry.update(event=event.kind, is_force=event.is_force,
                             payload=plain(event.payload))
                if event.is_force:
                    force = event.force()
                    entry.update(force=list(force.force), point=list(force.point),
                                 duration=force.duration)
            line["chunks"].append(entry)
        lines.write(json.dumps(line) + "\n")
