// vrflow._app: the application library (vrflow::app, vrflow::run's prepare) for Python. The
// builder in vrflow/app.py stands on it; docs/python-apps.md describes both.
#include "bindings.hpp"

PYBIND11_MODULE(_app, module) {
  module.doc() = "vrflow's application model, loader, writer and checks (see vrflow.app)";
  vrflow::python::bindModel(module);
  vrflow::python::bindFiles(module);
}
