#pragma once
// The pieces of the extension vrflow._app (python/app/module.cpp joins them): the application
// model of vrflow::app as Python classes, and loading, saving and checking it.

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl_bind.h>

#include <vector>

#include "vrflow/app/model.hpp"

// The model's lists are bound by reference (appending to `app.modules` changes the model), not
// copied to and from Python lists as pybind11/stl.h would.
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::Param>)
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::Host>)
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::Module>)
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::InputConfig>)
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::Filter>)
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::Connection>)
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::Instance>)
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::Composite>)
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::EditorNode>)
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::EditorNote>)
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::EditorFrame>)
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::PackageFolder>)
PYBIND11_MAKE_OPAQUE(std::vector<vrflow::app::SectionComments>)

namespace vrflow::python {

/// Binds the model's types (model.hpp, composite.hpp) into `module`.
void bindModel(pybind11::module_& module);
/// Binds loading, saving and checking applications and composites (loader, writer, prepare).
void bindFiles(pybind11::module_& module);

}  // namespace vrflow::python
