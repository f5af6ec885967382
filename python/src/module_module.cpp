#include <pybind11/stl.h>

#include <memory>
#include <string>

#include "module_bindings.hpp"
#include "vrflow/message/object_type.hpp"

namespace vrflow::python {
namespace {

namespace py = pybind11;

/// Python's Module. close(), a with-block's end or the interpreter's exit leaves the loop
/// (Module::leave()); the C++ Module, whose segment the messages live in, is destroyed only
/// after every message, outgoing message and view taken from it (they keep it alive).
struct PyModule {
  std::unique_ptr<Module> module = std::make_unique<Module>();
  Module& get() { return *module; }
};

// A parameter's value as Python reads it, or vrflow.ParameterError with the C++ API's message
// (naming the module and the parameter) when the manifest does not declare it with a value.
py::object parameter(PyModule& self, const std::string& name) {
  const Parameters& params = self.get().params();
  const auto found = params.entries().find(name);
  if (found == params.entries().end() || !found->second.value) {
    Parameters probe = params;  // the C++ reader's message, without its exit
    probe.setFailureHandler(nullptr);
    (void)probe.getString(name);
    throw ParameterError(probe.firstError() ? probe.firstError()->message
                                            : "cannot read parameter '" + name + "'");
  }
  return std::visit([](const auto& value) { return py::cast(value); }, *found->second.value);
}

py::dict parameters(PyModule& self) {
  py::dict result;
  for (const auto& [name, entry] : self.get().params().entries()) {
    if (!entry.value) continue;
    result[py::str(name)] =
        std::visit([](const auto& value) { return py::cast(value); }, *entry.value);
  }
  return result;
}

// Sends; false when the run stops, vrflow.Error when the module failed (shared memory full).
template <typename Send>
bool send(Module& module, Send&& doSend) {
  Status status;
  {
    py::gil_scoped_release release;  // put() blocks while the port's buffer is full
    status = doSend();
  }
  if (status) return true;
  if (module.exitStatus() != 0) throw Error(status.error().message);
  return false;
}

void registerType(const std::string& name,
                  const std::vector<std::pair<std::string, std::string>>& params) {
  static const std::map<std::string, msg::ParamKind> kinds{
      {"scalar", msg::ParamKind::Scalar},
      {"vec3", msg::ParamKind::Vec3},
      {"quat", msg::ParamKind::Quat},
      {"mat3", msg::ParamKind::Mat3},
      {"aabb", msg::ParamKind::Aabb},
      {"id", msg::ParamKind::Id},
      {"int64", msg::ParamKind::Int64},
      {"bytes", msg::ParamKind::Bytes},
      {"float_array", msg::ParamKind::FloatArray},
      {"double_array", msg::ParamKind::DoubleArray}};
  std::vector<msg::ParamDecl> decls;
  for (const auto& [param, kind] : params) {
    const auto found = kinds.find(kind);
    if (found == kinds.end()) {
      throw Error("parameter '" + param + "' of type '" + name + "' has kind '" + kind +
                  "': use scalar, vec3, quat, mat3, aabb, id, int64, bytes, float_array or "
                  "double_array");
    }
    decls.push_back({param, found->second});
  }
  auto type = msg::ObjectType::create(name, std::move(decls));
  if (!type) throw Error(type.error().message);
  auto added = msg::ObjectTypeRegistry::global().add(std::move(*type));
  if (!added) throw Error(added.error().message);
}

}  // namespace

void bindModule(py::module_& m) {
  py::class_<InputPort>(m, "InputPort")
      .def_property_readonly("name", &InputPort::name)
      .def_property_readonly("connected", &InputPort::connected);
  py::class_<OutputPort>(m, "OutputPort")
      .def_property_readonly("name", &OutputPort::name)
      .def_property_readonly("connected", &OutputPort::connected);

  py::class_<PyModule>(m, "Module", "One module process: declare ports, init(), loop on wait()")
      .def(py::init<>())
      .def(
          "add_input", [](PyModule& s, std::string name) { return &s.get().addInput(name); },
          py::return_value_policy::reference_internal, py::arg("name"))
      .def(
          "add_output", [](PyModule& s, std::string name) { return &s.get().addOutput(name); },
          py::return_value_policy::reference_internal, py::arg("name"))
      .def("init",
           [](PyModule& s) {
             if (auto status = s.get().init(); !status) throw Error(status.error().message);
           })
      .def("wait",
           [](PyModule& s) {
             Module& module = s.get();
             py::gil_scoped_release release;
             return module.wait();
           })
      .def(
          "get", [](PyModule& s, const InputPort& port) { return s.get().get(port); },
          py::keep_alive<0, 1>())
      .def(
          "new_message",
          [](PyModule& s, std::size_t sizeHint) {
            Outgoing outgoing;
            outgoing.message.emplace(s.get().newMessage(sizeHint));
            return outgoing;
          },
          py::arg("size_hint") = 256, py::keep_alive<0, 1>())
      .def("put",
           [](PyModule& s, const OutputPort& port, Outgoing& out) {
             Module& module = s.get();
             out.builder();  // raises when already sent
             OutgoingMessage message = std::move(*out.message);
             out.message.reset();
             out.viewBase = nullptr;
             return send(module, [&] { return module.put(port, std::move(message)); });
           })
      .def("put",
           [](PyModule& s, const OutputPort& port, const Message& message) {
             Module& module = s.get();
             return send(module, [&] { return module.put(port, message); });
           })
      .def(
          "seal",
          [](PyModule& s, Outgoing& out) {
            out.builder();
            OutgoingMessage message = std::move(*out.message);
            out.message.reset();
            out.viewBase = nullptr;
            auto sealed = s.get().seal(std::move(message));
            if (!sealed) throw Error(sealed.error().message);
            return std::move(*sealed);
          },
          py::keep_alive<0, 1>())
      .def_property_readonly("id", [](PyModule& s) { return s.get().id(); })
      .def_property_readonly("iteration", [](PyModule& s) { return s.get().iteration(); })
      .def_property_readonly("sim_time", [](PyModule& s) { return s.get().simTime(); })
      .def_property_readonly("time_step", [](PyModule& s) { return s.get().timeStep(); })
      .def_property_readonly("stop_requested", [](PyModule& s) { return s.get().stopRequested(); })
      .def_property_readonly("exit_status", [](PyModule& s) { return s.get().exitStatus(); })
      .def("_param", &parameter, py::arg("name"))
      .def("_params", &parameters)
      .def("new_id", [](PyModule& s) { return s.get().newId(); })
      .def("close", [](PyModule& s) {
        py::gil_scoped_release release;
        s.get().leave();
      });

  m.def("register_type", &registerType, py::arg("name"), py::arg("params"),
        "Registers an object type: a name and its (parameter, kind) pairs in index order");
}

}  // namespace vrflow::python
