#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <string>

#include "module_bindings.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::python {

msg::MessageBuilder& Outgoing::builder() {
  if (!message) throw Error("this message was sent or sealed: start another with new_message()");
  return message->builder();
}

void Outgoing::checkViewsStayed() {
  if (viewBase == nullptr) return;
  const std::byte* base = message->builder().bytes().data();
  if (base == viewBase) return;
  viewBase = nullptr;
  throw Error(
      "the message grew and moved after new_raw_resource() handed out a writable view, which "
      "now points at its old place: reserve the message's size up front with "
      "new_message(size_hint=BYTES), or add that resource last");
}

namespace {

namespace py = pybind11;
using msg::ParamKind;

/// An object chunk's parameters being written (valid until the next chunk is added).
struct ObjectWriterRef {
  py::object owner;  // the Python OutgoingMessage
  msg::ObjectWriter writer;
  std::uint32_t chunk;  // its chunk index
};

template <typename T>
void requireFinite(std::span<const T> values, const std::string& what) {
  for (const T v : values) {
    if (!std::isfinite(v)) throw py::value_error(what + " holds NaN or infinity");
  }
}

template <typename T>
using Dense = py::array_t<T, py::array::c_style | py::array::forcecast>;

template <std::size_t N>
std::array<double, N> doublesOf(const py::handle& value, const std::string& what) {
  const Dense<double> array = Dense<double>::ensure(value);
  if (!array || static_cast<std::size_t>(array.size()) != N) {
    throw py::value_error(what + " expects " + std::to_string(N) + " numbers");
  }
  std::array<double, N> out{};
  std::copy_n(array.data(), N, out.begin());
  requireFinite(std::span<const double>(out), what);
  return out;
}

template <typename T>
Dense<T> arrayOf(const py::handle& value, const std::string& what) {
  Dense<T> array = Dense<T>::ensure(value);
  if (!array) throw py::value_error(what + " expects an array of numbers");
  return array;
}

template <typename T>
std::span<const T> spanOf(const Dense<T>& array) {
  return {array.data(), static_cast<std::size_t>(array.size())};
}

std::span<const std::byte> bytesOf(const py::buffer_info& info) {
  return {static_cast<const std::byte*>(info.ptr),
          static_cast<std::size_t>(info.size * info.itemsize)};
}

void setParam(ObjectWriterRef& ref, const py::handle& key, const py::handle& value) {
  auto& outgoing = ref.owner.cast<Outgoing&>();
  if (!outgoing.message || outgoing.builder().chunkCount() != ref.chunk + 1) {
    throw Error(
        "this object's writer is closed: set an object's parameters before adding the "
        "next chunk or sending the message");
  }
  const msg::ObjectType& type = ref.writer.type();
  std::size_t index = 0;
  if (py::isinstance<py::str>(key)) {
    const auto name = key.cast<std::string>();
    const auto found = type.indexOf(name);
    if (!found) throw Error("object type '" + type.name() + "' has no parameter '" + name + "'");
    index = *found;
  } else {
    const auto i = key.cast<long long>();
    if (i < 0 || static_cast<std::size_t>(i) >= type.paramCount()) {
      throw Error("object type '" + type.name() + "' has no parameter " + std::to_string(i));
    }
    index = static_cast<std::size_t>(i);
  }
  const msg::ParamDecl& decl = type.param(index);
  const std::string what = "parameter '" + decl.name + "' of '" + type.name() + "'";
  msg::ObjectWriter& w = ref.writer;
  switch (decl.kind) {
    case ParamKind::Scalar:
      w.set(index, doublesOf<1>(value, what)[0]);
      break;
    case ParamKind::Vec3:
      w.set(index, doublesOf<3>(value, what));
      break;
    case ParamKind::Quat:
      w.set(index, doublesOf<4>(value, what));
      break;
    case ParamKind::Mat3:
      w.set(index, doublesOf<9>(value, what));
      break;
    case ParamKind::Aabb: {
      const auto box = doublesOf<6>(value, what + " (min, max)");
      w.set(index, msg::Aabb{{box[0], box[1], box[2]}, {box[3], box[4], box[5]}});
      break;
    }
    case ParamKind::Id:
      w.set(index, value.cast<std::uint64_t>());
      break;
    case ParamKind::Int64:
      w.set(index, value.cast<std::int64_t>());
      break;
    case ParamKind::FloatArray: {
      const auto array = arrayOf<float>(value, what);
      requireFinite(spanOf(array), what);
      w.set(index, spanOf(array));
      break;
    }
    case ParamKind::DoubleArray: {
      const auto array = arrayOf<double>(value, what);
      requireFinite(spanOf(array), what);
      w.set(index, spanOf(array));
      break;
    }
    case ParamKind::Bytes: {
      const py::buffer buffer = py::reinterpret_borrow<py::buffer>(value);
      w.set(index, bytesOf(buffer.request()));
      break;
    }
  }
  outgoing.checkViewsStayed();
}

const msg::ObjectType& typeNamed(const std::string& name) {
  const msg::ObjectType* type = msg::ObjectTypeRegistry::global().find(std::string_view(name));
  if (type == nullptr) {
    throw Error("unknown object type '" + name + "': register it with vrflow.register_type()");
  }
  return *type;
}

py::object addObject(const py::object& self, std::uint64_t id, const std::string& typeName,
                     const std::string& op) {
  auto& outgoing = self.cast<Outgoing&>();
  auto& builder = outgoing.builder();
  if (op != "add" && op != "update") {
    throw py::value_error("op is 'add' or 'update' (delete with add_delete()), not '" + op + "'");
  }
  const msg::ObjectType& type = typeNamed(typeName);
  msg::ObjectWriter writer =
      builder.addObject(id, type, op == "add" ? msg::ObjectOp::Add : msg::ObjectOp::Update);
  outgoing.checkViewsStayed();
  return py::cast(ObjectWriterRef{self, writer, builder.chunkCount() - 1});
}

py::array newRawResource(const py::object& self, std::uint64_t id, std::size_t size, bool dynamic) {
  auto& outgoing = self.cast<Outgoing&>();
  auto& builder = outgoing.builder();
  const std::span<std::byte> body = builder.addRawResourceInPlace(id, dynamic, size);
  outgoing.checkViewsStayed();
  if (body.data() == nullptr && size != 0) {
    throw Error("shared memory exhausted while adding a " + std::to_string(size) +
                "-byte resource (raise vrflow run --shm-size)");
  }
  outgoing.viewBase = builder.bytes().data();
  return viewOf<std::uint8_t>(body.data(), size, self, /*writable=*/true);
}

void addMesh(Outgoing& outgoing, std::uint64_t id, const py::handle& vertices,
             const py::handle& indices, bool dynamic) {
  const auto xyz = arrayOf<float>(vertices, "mesh vertices");
  const auto triangles = arrayOf<std::uint32_t>(indices, "mesh indices");
  if (xyz.size() % 3 != 0 || triangles.size() % 3 != 0) {
    throw py::value_error("a mesh has 3 coordinates per vertex and 3 indices per triangle");
  }
  const auto vertexCount = static_cast<std::size_t>(xyz.size() / 3);
  for (const std::uint32_t index : spanOf(triangles)) {
    if (index >= vertexCount) {
      throw py::value_error("mesh index " + std::to_string(index) + " is beyond its " +
                            std::to_string(vertexCount) + " vertices");
    }
  }
  requireFinite(spanOf(xyz), "mesh vertices");
  outgoing.builder().addMesh(id, dynamic, spanOf(xyz), spanOf(triangles));
  outgoing.checkViewsStayed();
}

void addField(Outgoing& outgoing, std::uint64_t id, const py::handle& data, msg::Vec3 origin,
              double spacing, bool dynamic) {
  const auto values = arrayOf<float>(data, "field data");
  // (nz, ny, nx) for a scalar field, (nz, ny, nx, 3) for a vector field: x fastest.
  const auto rank = values.ndim();
  if (rank != 3 && !(rank == 4 && values.shape(3) == 3)) {
    throw py::value_error("field data is shaped (nz, ny, nx) or (nz, ny, nx, 3)");
  }
  const std::array<std::uint32_t, 3> dims{static_cast<std::uint32_t>(values.shape(2)),
                                          static_cast<std::uint32_t>(values.shape(1)),
                                          static_cast<std::uint32_t>(values.shape(0))};
  requireFinite(spanOf(values), "field data");
  requireFinite(std::span<const double>(origin), "field origin");
  if (!std::isfinite(spacing) || spacing <= 0) throw py::value_error("field spacing must be > 0");
  outgoing.builder().addField(id, dynamic, dims, rank == 4 ? 3u : 1u, origin, spacing,
                              spanOf(values));
  outgoing.checkViewsStayed();
}

void addStamp(Outgoing& outgoing, const std::string& name, const py::handle& value) {
  if (name.empty() || name.size() > std::numeric_limits<std::uint16_t>::max()) {
    throw py::value_error("a stamp's name has 1 to 65535 bytes");
  }
  auto& builder = outgoing.builder();
  if (py::isinstance<py::bool_>(value) || py::isinstance<py::int_>(value)) {
    builder.addInt64Stamp(name, value.cast<std::int64_t>());
  } else if (py::isinstance<py::float_>(value)) {
    builder.addDoubleStamp(name, value.cast<double>());
  } else if (py::isinstance<py::str>(value)) {
    builder.addStringStamp(name, value.cast<std::string>());
  } else {
    throw py::type_error("a stamp's value is an int, a float or a str");
  }
  outgoing.checkViewsStayed();
}

}  // namespace

void bindBuilder(py::module_& m) {
  py::class_<ObjectWriterRef>(m, "ObjectWriter",
                              "Sets the parameters of an object chunk being written")
      .def(
          "set",
          [](py::object self, const py::handle& key, const py::handle& value) {
            setParam(self.cast<ObjectWriterRef&>(), key, value);
            return self;
          },
          py::arg("key"), py::arg("value"),
          "Sets parameter `key` (a name of the type, or an index); returns the writer")
      .def("__setitem__", [](ObjectWriterRef& ref, const py::handle& key, const py::handle& value) {
        setParam(ref, key, value);
      });

  py::class_<Outgoing>(m, "OutgoingMessage",
                       "A message written straight into shared memory; send it with put()")
      .def("add_object", &addObject, py::arg("id"), py::arg("type"), py::arg("op") = "update",
           "Starts an object chunk of a registered type; set its parameters on the writer")
      .def(
          "add_delete",
          [](Outgoing& o, std::uint64_t id, const std::string& type) {
            o.builder().addDelete(id, typeNamed(type));
            o.checkViewsStayed();
          },
          py::arg("id"), py::arg("type"))
      .def(
          "add_raw_resource",
          [](Outgoing& o, std::uint64_t id, const py::buffer& data, bool dynamic) {
            const py::buffer_info info = data.request();
            o.builder().addRawResource(id, dynamic, bytesOf(info));
            o.checkViewsStayed();
          },
          py::arg("id"), py::arg("data"), py::arg("dynamic") = true,
          "Adds a raw resource copied from any buffer")
      .def("new_raw_resource", &newRawResource, py::arg("id"), py::arg("nbytes"),
           py::arg("dynamic") = true,
           "Adds a raw resource of nbytes and returns a writable uint8 view of it in shared "
           "memory (zero copy; its bytes are not cleared)")
      .def("add_mesh", &addMesh, py::arg("id"), py::arg("vertices"), py::arg("indices"),
           py::arg("dynamic") = false)
      .def("add_field", &addField, py::arg("id"), py::arg("data"), py::arg("origin") = msg::Vec3{},
           py::arg("spacing") = 1.0, py::arg("dynamic") = true)
      .def(
          "add_force",
          [](Outgoing& o, std::uint64_t target, msg::Vec3 force, msg::Vec3 torque, msg::Vec3 point,
             double duration) {
            const msg::ForceEvent event{force, torque, point, duration};
            for (const auto* v : {&event.force, &event.torque, &event.point}) {
              requireFinite(std::span<const double>(*v), "a force event");
            }
            requireFinite(std::span<const double>(&event.duration, 1), "a force event");
            o.builder().addForce(target, event);
            o.checkViewsStayed();
          },
          py::arg("target"), py::arg("force") = msg::Vec3{}, py::arg("torque") = msg::Vec3{},
          py::arg("point") = msg::Vec3{}, py::arg("duration") = 0.0)
      .def(
          "add_event",
          [](Outgoing& o, std::uint64_t id, int kind, const py::buffer& payload) {
            if (kind < msg::kFirstUserEventKind || kind > 65535) {
              throw py::value_error("user event kinds are 1024..65535 (forces: add_force())");
            }
            const py::buffer_info info = payload.request();
            o.builder().addEvent(id, static_cast<std::uint16_t>(kind), bytesOf(info));
            o.checkViewsStayed();
          },
          py::arg("id"), py::arg("kind"), py::arg("payload"))
      .def(
          "append_chunks",
          [](Outgoing& o, const Message& message) {
            o.builder().appendChunks(message.view());
            o.checkViewsStayed();
          },
          "Copies every chunk of a received message")
      .def("add_stamp", &addStamp, py::arg("name"), py::arg("value"),
           "Adds a user stamp (int, float or str)")
      .def("set_sim_time", [](Outgoing& o, double t) { o.builder().setSimTime(t); })
      .def("set_time_step", [](Outgoing& o, double t) { o.builder().setTimeStep(t); })
      .def_property_readonly("nbytes", [](Outgoing& o) { return o.builder().size(); })
      .def("__len__", [](Outgoing& o) { return o.builder().chunkCount(); });
}

}  // namespace vrflow::python
