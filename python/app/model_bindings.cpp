// The application model (vrflow/app/model.hpp) as Python classes. Lists are bound by reference;
// keywords (a connection's policy, an input's mode, a module's endit) are their XML text.
#include <optional>
#include <string>
#include <string_view>

#include "bindings.hpp"
#include "vrflow/app/composite.hpp"
#include "vrflow/app/model.hpp"

namespace py = pybind11;

namespace vrflow::python {
namespace {

using namespace vrflow::app;

// A keyword attribute read and written as its XML text; a word it does not know is a ValueError
// that lists the ones it does.
template <typename Class, typename Enum>
void keywordProperty(py::class_<Class>& cls, const char* name, Enum Class::*member,
                     std::optional<Enum> (*parse)(std::string_view), const char* allowed) {
  cls.def_property(
      name, [member](const Class& self) { return toString(self.*member); },
      [member, parse, name, allowed](Class& self, const std::string& text) {
        const auto value = parse(text);
        if (!value) {
          throw py::value_error(std::string(name) + " must be one of " + allowed + ", got '" +
                                text + "'");
        }
        self.*member = *value;
      });
}

// `comments`: the XML comments written before an element, as a Python list of str (copied).
template <typename Class>
void commentsProperty(py::class_<Class>& cls) {
  cls.def_readwrite("comments", &Class::comments);
}

void bindLocation(py::module_& module) {
  py::class_<SourceLocation>(module, "SourceLocation")
      .def_readonly("file", &SourceLocation::file)
      .def_readonly("line", &SourceLocation::line)
      .def_readonly("column", &SourceLocation::column);
}

void bindNodes(py::module_& module) {
  py::class_<Param> param(module, "Param");
  param
      .def(py::init([](std::string name, std::string value) {
             return Param{.name = std::move(name), .value = std::move(value), .loc = {}};
           }),
           py::arg("name"), py::arg("value"))
      .def_readwrite("name", &Param::name)
      .def_readwrite("value", &Param::value)
      .def_readonly("loc", &Param::loc);
  commentsProperty(param);
  py::bind_vector<std::vector<Param>>(module, "ParamList")
      .def(
          "set",
          [](std::vector<Param>& params, std::string_view name, std::string value) {
            setParam(params, name, std::move(value));
          },
          "Sets a parameter, replacing its value when present, appending it otherwise")
      .def("find", [](std::vector<Param>& params, std::string_view name) -> py::object {
        const Param* found = findParam(params, name);
        return found == nullptr ? py::none() : py::cast(found->value);
      });

  py::class_<Host> host(module, "Host");
  host.def(py::init<>())
      .def_readwrite("id", &Host::id)
      .def_readwrite("address", &Host::address)
      .def_readonly("loc", &Host::loc);
  commentsProperty(host);
  py::bind_vector<std::vector<Host>>(module, "HostList");

  py::class_<InputConfig> input(module, "InputConfig");
  input.def(py::init<>())
      .def_readwrite("port", &InputConfig::port)
      .def_readwrite("initial_messages", &InputConfig::initialMessages)
      .def_readonly("loc", &InputConfig::loc);
  keywordProperty(input, "mode", &InputConfig::mode, &parseInputMode, "fifo, latest");
  commentsProperty(input);
  py::bind_vector<std::vector<InputConfig>>(module, "InputConfigList");

  py::class_<Module> mod(module, "Module");
  mod.def(py::init<>())
      .def_readwrite("id", &Module::id)
      .def_readwrite("package", &Module::package)
      .def_readwrite("type", &Module::type)
      .def_readwrite("host", &Module::host)
      .def_readwrite("params", &Module::params, py::return_value_policy::reference_internal)
      .def_readwrite("inputs", &Module::inputs, py::return_value_policy::reference_internal)
      .def_readwrite("end_comments", &Module::endComments)
      .def_readonly("loc", &Module::loc);
  keywordProperty(mod, "endit", &Module::endIt, &parseEndItTiming, "after-iteration, after-wait");
  commentsProperty(mod);
  py::bind_vector<std::vector<Module>>(module, "ModuleList");

  py::class_<Filter> filter(module, "Filter");
  filter.def(py::init<>())
      .def_readwrite("id", &Filter::id)
      .def_readwrite("type", &Filter::type)
      .def_readwrite("host", &Filter::host)
      .def_readwrite("plugin", &Filter::plugin)
      .def_readwrite("params", &Filter::params, py::return_value_policy::reference_internal)
      .def_readwrite("end_comments", &Filter::endComments)
      .def_readonly("loc", &Filter::loc);
  commentsProperty(filter);
  py::bind_vector<std::vector<Filter>>(module, "FilterList");
}

void bindConnections(py::module_& module) {
  py::class_<Endpoint>(module, "Endpoint")
      .def(py::init([](std::string node, std::string port) {
             return Endpoint{std::move(node), std::move(port)};
           }),
           py::arg("node"), py::arg("port"))
      .def_readwrite("node", &Endpoint::node)
      .def_readwrite("port", &Endpoint::port)
      .def("__str__", [](const Endpoint& endpoint) { return toString(endpoint); });

  py::class_<Connection> connection(module, "Connection");
  connection.def(py::init<>())
      .def_readwrite("source", &Connection::from)
      .def_readwrite("target", &Connection::to)
      .def_readwrite("capacity", &Connection::capacity)
      .def_readonly("loc", &Connection::loc);
  keywordProperty(connection, "policy", &Connection::policy, &parseQueuePolicy,
                  "block, drop-oldest, drop-newest");
  commentsProperty(connection);
  py::bind_vector<std::vector<Connection>>(module, "ConnectionList");

  py::class_<Instance> instance(module, "Instance");
  instance.def(py::init<>())
      .def_readwrite("id", &Instance::id)
      .def_readwrite("composite", &Instance::composite)
      .def_readwrite("host", &Instance::host)
      .def_readwrite("params", &Instance::params, py::return_value_policy::reference_internal)
      .def_readonly("loc", &Instance::loc);
  commentsProperty(instance);
  py::bind_vector<std::vector<Instance>>(module, "InstanceList");

  // A composite is read from its file (load_composite) and kept whole; its body is a template.
  py::class_<Composite>(module, "Composite")
      .def_readonly("name", &Composite::name)
      .def_readonly("doc", &Composite::doc)
      .def_property_readonly("inputs",
                             [](const Composite& composite) {
                               std::vector<std::string> names;
                               for (const auto& port : composite.inputs) names.push_back(port.name);
                               return names;
                             })
      .def_property_readonly("outputs",
                             [](const Composite& composite) {
                               std::vector<std::string> names;
                               for (const auto& port : composite.outputs) {
                                 names.push_back(port.name);
                               }
                               return names;
                             })
      .def_property_readonly("params", [](const Composite& composite) {
        std::vector<std::string> names;
        for (const auto& param : composite.params) names.push_back(param.name);
        return names;
      });
  py::bind_vector<std::vector<Composite>>(module, "CompositeList");
}

void bindEditor(py::module_& module) {
  py::class_<EditorNode> node(module, "EditorNode");
  node.def(py::init<std::string, double, double>(), py::arg("ref"), py::arg("x") = 0.0,
           py::arg("y") = 0.0)
      .def_readwrite("ref", &EditorNode::ref)
      .def_readwrite("x", &EditorNode::x)
      .def_readwrite("y", &EditorNode::y);
  commentsProperty(node);
  py::bind_vector<std::vector<EditorNode>>(module, "EditorNodeList");

  py::class_<EditorNote> note(module, "EditorNote");
  note.def(py::init<>())
      .def_readwrite("id", &EditorNote::id)
      .def_readwrite("x", &EditorNote::x)
      .def_readwrite("y", &EditorNote::y)
      .def_readwrite("width", &EditorNote::width)
      .def_readwrite("height", &EditorNote::height)
      .def_readwrite("text", &EditorNote::text);
  commentsProperty(note);
  py::bind_vector<std::vector<EditorNote>>(module, "EditorNoteList");

  py::class_<EditorFrame> frame(module, "EditorFrame");
  frame.def(py::init<>())
      .def_readwrite("id", &EditorFrame::id)
      .def_readwrite("title", &EditorFrame::title)
      .def_readwrite("x", &EditorFrame::x)
      .def_readwrite("y", &EditorFrame::y)
      .def_readwrite("width", &EditorFrame::width)
      .def_readwrite("height", &EditorFrame::height)
      .def_readwrite("color", &EditorFrame::color);
  commentsProperty(frame);
  py::bind_vector<std::vector<EditorFrame>>(module, "EditorFrameList");
}

void bindApplication(py::module_& module) {
  py::class_<PackageFolder> folder(module, "PackageFolder");
  folder
      .def(py::init(
               [](std::string path) { return PackageFolder{.path = std::move(path), .loc = {}}; }),
           py::arg("path"))
      .def_readwrite("path", &PackageFolder::path);
  commentsProperty(folder);
  py::bind_vector<std::vector<PackageFolder>>(module, "PackageFolderList");

  py::class_<SectionComments>(module, "SectionComments")
      .def(py::init([](std::string section, Comments before, Comments end) {
             return SectionComments{std::move(section), std::move(before), std::move(end)};
           }),
           py::arg("section"), py::arg("before") = Comments{}, py::arg("end") = Comments{})
      .def_readwrite("section", &SectionComments::section)
      .def_readwrite("before", &SectionComments::before)
      .def_readwrite("end", &SectionComments::end);
  py::bind_vector<std::vector<SectionComments>>(module, "SectionCommentsList");

  const auto ref = py::return_value_policy::reference_internal;
  py::class_<Application> application(module, "Application");
  application.def(py::init<>())
      .def_readwrite("name", &Application::name)
      .def_readwrite("file", &Application::file)
      .def_readwrite("packages", &Application::packages, ref)
      .def_readwrite("hosts", &Application::hosts, ref)
      .def_readwrite("composites", &Application::composites, ref)
      .def_readwrite("modules", &Application::modules, ref)
      .def_readwrite("instances", &Application::instances, ref)
      .def_readwrite("filters", &Application::filters, ref)
      .def_readwrite("connections", &Application::connections, ref)
      .def_readwrite("editor", &Application::editor, ref)
      .def_readwrite("notes", &Application::notes, ref)
      .def_readwrite("frames", &Application::frames, ref)
      .def_readwrite("end_comments", &Application::endComments)
      .def_readwrite("after_comments", &Application::afterComments)
      .def_readwrite("section_comments", &Application::sectionComments, ref);
  commentsProperty(application);
}

}  // namespace

void bindModel(py::module_& module) {
  bindLocation(module);
  bindNodes(module);
  bindConnections(module);
  bindEditor(module);
  bindApplication(module);
}

}  // namespace vrflow::python
