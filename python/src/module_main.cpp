#include "module_bindings.hpp"

// vrflow._module: the module API for Python (docs/python.md). The `vrflow` package re-exports it.
PYBIND11_MODULE(_module, m) {
  namespace py = pybind11;
  m.doc() = "vrflow's module API: ports, wait(), get(), messages viewed in shared memory";
  static py::exception<vrflow::python::Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<vrflow::python::ParameterError> parameterError(m, "ParameterError",
                                                                      error.ptr());
  py::register_exception_translator([](std::exception_ptr thrown) {
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const vrflow::python::ParameterError& e) {
      parameterError(e.what());
    } catch (const vrflow::python::Error& e) {
      error(e.what());
    }
  });
  vrflow::python::bindMessages(m);
  vrflow::python::bindBuilder(m);
  vrflow::python::bindModule(m);
}
