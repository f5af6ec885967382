#include <pybind11/stl.h>

#include <string>

#include "module_bindings.hpp"
#include "vrflow/message/reader.hpp"
#include "vrflow/module/message.hpp"

namespace vrflow::python {
namespace {

namespace py = pybind11;
using msg::ParamKind;

/// A chunk of a message, kept alive by the Python Message it came from.
struct Chunk {
  py::object owner;
  msg::ChunkView view;
};
/// An object chunk, a resource chunk, an event chunk: their typed views and their owner.
struct ObjectChunk {
  py::object owner;
  msg::ObjectView view;
};
struct ResourceChunk {
  py::object owner;
  msg::ResourceView view;
};
struct EventChunk {
  py::object owner;
  msg::EventView view;
};

const char* kindName(msg::ChunkKind kind) {
  switch (kind) {
    case msg::ChunkKind::Object:
      return "object";
    case msg::ChunkKind::Resource:
      return "resource";
    case msg::ChunkKind::Event:
      return "event";
  }
  return "unknown";
}

const char* opName(msg::ObjectOp op) {
  switch (op) {
    case msg::ObjectOp::Add:
      return "add";
    case msg::ObjectOp::Update:
      return "update";
    case msg::ObjectOp::Delete:
      return "delete";
  }
  return "unknown";
}

const char* resourceKindName(msg::ResourceKind kind) {
  switch (kind) {
    case msg::ResourceKind::Raw:
      return "raw";
    case msg::ResourceKind::Mesh:
      return "mesh";
    case msg::ResourceKind::ScalarField:
      return "scalar_field";
    case msg::ResourceKind::VectorField:
      return "vector_field";
  }
  return "unknown";
}

// A parameter's value as Python reads it: float, tuple, int, or a read-only NumPy view of the
// message's bytes for arrays and bytes. None when it does not travel in this chunk.
py::object paramValue(const ObjectChunk& object, std::size_t index) {
  const msg::ObjectView& view = object.view;
  const auto bytes = view.param(index);
  if (!bytes) return py::none();
  const msg::ObjectType* type = view.type();
  if (type == nullptr || index >= type->paramCount()) return byteView(*bytes, object.owner);
  switch (type->param(index).kind) {
    case ParamKind::Scalar:
      return py::cast(*view.scalar(index));
    case ParamKind::Vec3:
      return py::cast(*view.vec3(index));
    case ParamKind::Quat:
      return py::cast(*view.quat(index));
    case ParamKind::Mat3:
      return py::cast(*view.mat3(index));
    case ParamKind::Aabb: {
      const msg::Aabb box = *view.aabb(index);
      return py::make_tuple(box.min, box.max);
    }
    case ParamKind::Id:
      return py::cast(*view.idParam(index));
    case ParamKind::Int64:
      return py::cast(*view.int64(index));
    case ParamKind::FloatArray:
      return viewOf<float>(bytes->data(), bytes->size() / sizeof(float), object.owner);
    case ParamKind::DoubleArray:
      return viewOf<double>(bytes->data(), bytes->size() / sizeof(double), object.owner);
    case ParamKind::Bytes:
      return byteView(*bytes, object.owner);
  }
  return py::none();
}

// The index of parameter `key` (a name of the object's type, or an index).
std::size_t paramIndex(const msg::ObjectView& view, const py::handle& key) {
  if (py::isinstance<py::str>(key)) {
    const auto name = key.cast<std::string>();
    if (view.type() == nullptr) {
      throw Error("object " + std::to_string(view.id()) + " has a type unknown to this process (" +
                  std::to_string(view.typeId()) + "): read its parameters by index");
    }
    const auto index = view.type()->indexOf(name);
    if (!index) {
      throw Error("object type '" + view.type()->name() + "' has no parameter '" + name + "'");
    }
    return *index;
  }
  const auto index = key.cast<long long>();
  if (index < 0 || static_cast<std::size_t>(index) >= msg::kMaxParams) {
    throw Error("parameter index " + std::to_string(index) + " is outside 0..63");
  }
  return static_cast<std::size_t>(index);
}

py::object fieldOf(const ResourceChunk& resource) {
  const auto field = resource.view.field();
  if (!field) return py::none();
  const auto dims = field->dims();
  const auto raw = field->data().bytes();
  std::vector<py::ssize_t> shape{dims[2], dims[1], dims[0]};  // x fastest: C order (z, y, x)
  if (field->components() == 3) shape.push_back(3);
  py::array data =
      viewOf<float>(raw.data(), raw.size() / sizeof(float), resource.owner).attr("reshape")(shape);
  py::dict result;
  result["dims"] = dims;
  result["components"] = field->components();
  result["origin"] = field->origin();
  result["spacing"] = field->spacing();
  result["data"] = data;
  return result;
}

py::object meshOf(const ResourceChunk& resource) {
  const auto mesh = resource.view.mesh();
  if (!mesh) return py::none();
  const auto xyz = mesh->xyz().bytes();
  const auto indices = mesh->indices().bytes();
  py::dict result;
  result["vertices"] = viewOf<float>(xyz.data(), xyz.size() / sizeof(float), resource.owner)
                           .attr("reshape")(py::make_tuple(mesh->vertexCount(), 3));
  result["indices"] =
      viewOf<std::uint32_t>(indices.data(), indices.size() / sizeof(std::uint32_t), resource.owner)
          .attr("reshape")(py::make_tuple(mesh->triangleCount(), 3));
  return result;
}

py::dict userStamps(const Message& message) {
  py::dict stamps;
  for (const msg::UserStampView stamp : message->stamps().user) {
    const py::str name(std::string(stamp.name()));
    if (stamps.contains(name)) continue;  // the first one of a name, as find() does
    if (auto i = stamp.asInt64()) {
      stamps[name] = *i;
    } else if (auto d = stamp.asDouble()) {
      stamps[name] = *d;
    } else if (auto s = stamp.asString()) {
      stamps[name] = std::string(*s);
    }
  }
  return stamps;
}

py::list chunksOf(const py::object& self) {
  const auto& message = self.cast<const Message&>();
  py::list chunks;
  for (const msg::ChunkView chunk : message.view()) chunks.append(Chunk{self, chunk});
  return chunks;
}

}  // namespace

void bindMessages(py::module_& m) {
  py::class_<msg::ForceEvent>(m, "Force", "A force and torque at a world point over a duration")
      .def(py::init([](msg::Vec3 force, msg::Vec3 torque, msg::Vec3 point, double duration) {
             return msg::ForceEvent{force, torque, point, duration};
           }),
           py::arg("force") = msg::Vec3{}, py::arg("torque") = msg::Vec3{},
           py::arg("point") = msg::Vec3{}, py::arg("duration") = 0.0)
      .def_readwrite("force", &msg::ForceEvent::force)
      .def_readwrite("torque", &msg::ForceEvent::torque)
      .def_readwrite("point", &msg::ForceEvent::point)
      .def_readwrite("duration", &msg::ForceEvent::duration)
      .def("__repr__", [](const msg::ForceEvent& f) {
        return "Force(force=" + py::repr(py::cast(f.force)).cast<std::string>() +
               ", duration=" + std::to_string(f.duration) + ")";
      });

  py::class_<Message>(m, "Message",
                      "A message in shared memory, held by reference (docs/module-api.md)")
      .def_property_readonly("valid", &Message::valid)
      .def_property_readonly("source",
                             [](const Message& s) { return std::string(s->stamps().source); })
      .def_property_readonly("iteration", [](const Message& s) { return s->stamps().iteration; })
      .def_property_readonly("sim_time", [](const Message& s) { return s->stamps().simTime; })
      .def_property_readonly("time_step", [](const Message& s) { return s->stamps().timeStep; })
      .def_property_readonly("send_time_ns",
                             [](const Message& s) { return s->stamps().sendTimeNs; })
      .def_property_readonly("stamps_only", [](const Message& s) { return s->stampsOnly(); })
      .def_property_readonly("stamps", &userStamps, "The user stamps, by name")
      .def_property_readonly("nbytes", [](const Message& s) { return s.bytes().size(); })
      .def_property_readonly(
          "bytes",
          [](const py::object& self) {
            return byteView(self.cast<const Message&>().bytes(), self);
          },
          "A read-only uint8 view of the whole message (docs/message-layout.md)")
      .def("__len__", [](const Message& s) { return s->chunkCount(); })
      .def("chunks", &chunksOf, "The chunks, in order")
      .def("__iter__", [](const py::object& self) { return chunksOf(self).attr("__iter__")(); });

  py::class_<Chunk>(m, "Chunk", "One chunk of a message: header fields and typed views")
      .def_property_readonly("kind", [](const Chunk& c) { return kindName(c.view.kind()); })
      .def_property_readonly("index", [](const Chunk& c) { return c.view.index(); })
      .def_property_readonly("id", [](const Chunk& c) { return c.view.id(); })
      .def_property_readonly("op", [](const Chunk& c) { return c.view.op(); })
      .def_property_readonly("subkind", [](const Chunk& c) { return c.view.subkind(); })
      .def_property_readonly("type_id", [](const Chunk& c) { return c.view.typeId(); })
      .def_property_readonly("body",
                             [](const Chunk& c) { return byteView(c.view.body(), c.owner); })
      .def("as_object",
           [](const Chunk& c) -> py::object {
             if (auto o = c.view.asObject()) return py::cast(ObjectChunk{c.owner, *o});
             return py::none();
           })
      .def("as_resource",
           [](const Chunk& c) -> py::object {
             if (auto r = c.view.asResource()) return py::cast(ResourceChunk{c.owner, *r});
             return py::none();
           })
      .def("as_event", [](const Chunk& c) -> py::object {
        if (auto e = c.view.asEvent()) return py::cast(EventChunk{c.owner, *e});
        return py::none();
      });

  py::class_<ObjectChunk>(m, "ObjectView", "An object added, updated or deleted")
      .def_property_readonly("id", [](const ObjectChunk& o) { return o.view.id(); })
      .def_property_readonly("type_id", [](const ObjectChunk& o) { return o.view.typeId(); })
      .def_property_readonly("type",
                             [](const ObjectChunk& o) -> py::object {
                               if (o.view.type() == nullptr) return py::none();
                               return py::str(o.view.type()->name());
                             })
      .def_property_readonly("op", [](const ObjectChunk& o) { return opName(o.view.op()); })
      .def_property_readonly("mask", [](const ObjectChunk& o) { return o.view.mask(); })
      .def("has", [](const ObjectChunk& o,
                     const py::handle& key) { return o.view.has(paramIndex(o.view, key)); })
      .def("__getitem__",
           [](const ObjectChunk& o, const py::handle& key) {
             const std::size_t index = paramIndex(o.view, key);
             if (!o.view.has(index)) {
               throw py::key_error("parameter " + py::repr(key).cast<std::string>() +
                                   " does not travel in this chunk");
             }
             return paramValue(o, index);
           })
      .def(
          "get",
          [](const ObjectChunk& o, const py::handle& key, const py::object& fallback) {
            const std::size_t index = paramIndex(o.view, key);
            return o.view.has(index) ? paramValue(o, index) : fallback;
          },
          py::arg("key"), py::arg("default") = py::none())
      .def("params", [](const ObjectChunk& o) {
        py::dict params;
        for (const msg::ParamEntry entry : o.view.params()) {
          const msg::ObjectType* type = o.view.type();
          py::object key = type != nullptr && entry.index < type->paramCount()
                               ? py::object(py::str(type->param(entry.index).name))
                               : py::object(py::int_(entry.index));
          params[key] = paramValue(o, entry.index);
        }
        return params;
      });

  py::class_<ResourceChunk>(m, "ResourceView", "A resource: raw bytes, a mesh or a field")
      .def_property_readonly("id", [](const ResourceChunk& r) { return r.view.id(); })
      .def_property_readonly("kind",
                             [](const ResourceChunk& r) { return resourceKindName(r.view.kind()); })
      .def_property_readonly("dynamic", [](const ResourceChunk& r) { return r.view.dynamic(); })
      .def_property_readonly("data",
                             [](const ResourceChunk& r) { return byteView(r.view.raw(), r.owner); })
      .def("mesh", &meshOf, "vertices (n, 3) float32 and indices (t, 3) uint32 views, or None")
      .def("field", &fieldOf, "dims, components, origin, spacing and the data view, or None");

  py::class_<EventChunk>(m, "EventView", "An event for one object: a force or a user event")
      .def_property_readonly("id", [](const EventChunk& e) { return e.view.id(); })
      .def_property_readonly("kind", [](const EventChunk& e) { return e.view.kind(); })
      .def_property_readonly("is_force", [](const EventChunk& e) { return e.view.isForce(); })
      .def("force", [](const EventChunk& e) { return e.view.force(); })
      .def_property_readonly(
          "payload", [](const EventChunk& e) { return byteView(e.view.payload(), e.owner); });
}

}  // namespace vrflow::python
