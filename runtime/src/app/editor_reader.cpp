#include <algorithm>
#include <cctype>

#include "application_reader.hpp"
#include "text_util.hpp"
#include "validation.hpp"

namespace vrflow::app::detail {
namespace {

EditorNode readEditorNode(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node, {"ref", "x", "y"});
  EditorNode editorNode;
  editorNode.ref = reader.required("ref");
  editorNode.x = reader.number("x", 0);
  editorNode.y = reader.number("y", 0);
  editorNode.loc = reader.loc();
  editorNode.comments = commentsBefore(node);
  forEachChild(context, node, {}, [](const pugi::xml_node&) {});
  return editorNode;
}

// A width or height: a finite number above zero, or `fallback` after reporting another.
double readSize(const ElementReader& reader, const char* name, double fallback) {
  const std::optional<double> size = reader.optionalNumber(name);
  if (!size) return fallback;
  if (*size > 0) return *size;
  reader.errorAt(name,
                 reader.tag() + " " + name + " must be above 0, found " + formatNumber(*size));
  return fallback;
}

bool isColor(const std::string& text) {
  return text.size() == 7 && text[0] == '#' &&
         std::all_of(text.begin() + 1, text.end(),
                     [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; });
}

EditorNote readNote(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node, {"id", "x", "y", "width", "height"});
  EditorNote note;
  note.id = reader.required("id");
  note.x = reader.number("x", 0);
  note.y = reader.number("y", 0);
  note.width = readSize(reader, "width", note.width);
  note.height = readSize(reader, "height", note.height);
  note.text = readTextElement(context, node);
  note.loc = reader.loc();
  note.comments = commentsBefore(node);
  return note;
}

EditorFrame readFrame(const ReadContext& context, const pugi::xml_node& node) {
  const ElementReader reader(context, node, {"id", "title", "x", "y", "width", "height", "color"});
  EditorFrame frame;
  frame.id = reader.required("id");
  frame.title = reader.text("title");
  frame.x = reader.number("x", 0);
  frame.y = reader.number("y", 0);
  frame.width = readSize(reader, "width", frame.width);
  frame.height = readSize(reader, "height", frame.height);
  frame.color = reader.text("color");
  if (!frame.color.empty() && !isColor(frame.color)) {
    reader.errorAt("color", "<frame> color '" + frame.color + "' must be written #rrggbb");
    frame.color.clear();
  }
  frame.loc = reader.loc();
  frame.comments = commentsBefore(node);
  forEachChild(context, node, {}, [](const pugi::xml_node&) {});
  return frame;
}

// Notes and frames share one id namespace, apart from the modules' and filters'.
const SourceLocation* firstWithId(const Application& app, const std::string& id) {
  for (const EditorNote& note : app.notes) {
    if (note.id == id) return &note.loc;
  }
  for (const EditorFrame& frame : app.frames) {
    if (frame.id == id) return &frame.loc;
  }
  return nullptr;
}

void checkUniqueId(const ReadContext& context, const Application& app, const std::string& id,
                   const SourceLocation& loc, std::string_view element) {
  if (id.empty()) return;
  if (const SourceLocation* first = firstWithId(app, id)) {
    context.error(loc.attribute("id"), "<" + std::string(element) + "> id '" + id +
                                           "' is used twice (first" + atLine(*first) +
                                           "); notes and frames need distinct ids");
  }
}

}  // namespace

void readEditorSection(const ReadContext& context, const pugi::xml_node& section,
                       Application& app) {
  forEachChild(context, section, {"node", "note", "frame"}, [&](const pugi::xml_node& child) {
    const std::string_view name = child.name();
    if (name == "node") {
      app.editor.push_back(readEditorNode(context, child));
    } else if (name == "note") {
      EditorNote note = readNote(context, child);
      checkUniqueId(context, app, note.id, note.loc, name);
      app.notes.push_back(std::move(note));
    } else {
      EditorFrame frame = readFrame(context, child);
      checkUniqueId(context, app, frame.id, frame.loc, name);
      app.frames.push_back(std::move(frame));
    }
  });
}

}  // namespace vrflow::app::detail
