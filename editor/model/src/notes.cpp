#include "vrflow/editor/notes.hpp"

#include <algorithm>

namespace vrflow::editor {

namespace {

constexpr double kMinNoteWidth = 40;
constexpr double kMinNoteHeight = 24;
constexpr double kMinFrameWidth = 80;
constexpr double kMinFrameHeight = 50;

template <typename T>
T* findById(std::vector<T>& items, std::string_view id) {
  auto it = std::find_if(items.begin(), items.end(), [&](const T& t) { return t.id == id; });
  return it == items.end() ? nullptr : &*it;
}

template <typename T>
const T* findById(const std::vector<T>& items, std::string_view id) {
  auto it = std::find_if(items.begin(), items.end(), [&](const T& t) { return t.id == id; });
  return it == items.end() ? nullptr : &*it;
}

// An id no note or frame has: base, base2, base3, ...
std::string freshId(const app::Application& app, const std::string& base) {
  for (int n = 1;; ++n) {
    const std::string id = n == 1 ? base : base + std::to_string(n);
    if (findNote(app, id) == nullptr && findFrame(app, id) == nullptr) return id;
  }
}

Result<Edit> noSuch(std::string_view what, std::string_view id) {
  return makeError("no " + std::string(what) + " '" + std::string(id) + "'");
}

// Applies `change` to the element `id` of `list` (a member of a copy of `app`): the edit, or
// why not ("unchanged" when `change` returns false).
template <typename T, typename Change>
Result<Edit> changeOne(const app::Application& app, std::vector<T> app::Application::*list,
                       std::string_view what, std::string_view id, std::string label,
                       Change change) {
  app::Application after = app;
  T* item = findById(after.*list, id);
  if (item == nullptr) return noSuch(what, id);
  if (!change(*item)) return makeError("unchanged");
  return Edit{std::move(label), app, std::move(after)};
}

bool inside(double x, double y, const app::EditorFrame& frame) {
  return x >= frame.x && x <= frame.x + frame.width && y >= frame.y && y <= frame.y + frame.height;
}

}  // namespace

const app::EditorNote* findNote(const app::Application& app, std::string_view id) {
  return findById(app.notes, id);
}

const app::EditorFrame* findFrame(const app::Application& app, std::string_view id) {
  return findById(app.frames, id);
}

Result<Edit> addNote(const app::Application& app, double x, double y, std::string text,
                     std::string* newId) {
  app::Application after = app;
  app::EditorNote note;
  note.id = freshId(app, "note");
  note.x = x;
  note.y = y;
  note.text = std::move(text);
  if (newId != nullptr) *newId = note.id;
  after.notes.push_back(std::move(note));
  return Edit{"Add note", app, std::move(after)};
}

Result<Edit> addFrame(const app::Application& app, Rect area, std::string title,
                      std::string* newId) {
  app::Application after = app;
  app::EditorFrame frame;
  frame.id = freshId(app, "frame");
  frame.title = std::move(title);
  frame.x = area.x;
  frame.y = area.y;
  frame.width = std::max(kMinFrameWidth, area.width);
  frame.height = std::max(kMinFrameHeight, area.height);
  if (newId != nullptr) *newId = frame.id;
  after.frames.push_back(std::move(frame));
  return Edit{"Add frame", app, std::move(after)};
}

Result<Edit> setNoteArea(const app::Application& app, std::string_view id, Rect area) {
  app::Application after = app;
  auto* note = findById(after.notes, id);
  if (note == nullptr) return noSuch("note", id);
  const bool moved = note->x != area.x || note->y != area.y;
  note->x = area.x;
  note->y = area.y;
  note->width = std::max(kMinNoteWidth, area.width);
  note->height = std::max(kMinNoteHeight, area.height);
  const auto* old = findNote(app, id);
  if (old->x == note->x && old->y == note->y && old->width == note->width &&
      old->height == note->height)
    return makeError("unchanged");
  return Edit{moved ? "Move note" : "Resize note", app, std::move(after)};
}

Result<Edit> setNoteText(const app::Application& app, std::string_view id, std::string text) {
  return changeOne(app, &app::Application::notes, "note", id, "Edit note", [&](auto& note) {
    if (note.text == text) return false;
    note.text = std::move(text);
    return true;
  });
}

Result<Edit> setFrameArea(const app::Application& app, std::string_view id, Rect area) {
  app::Application after = app;
  auto* frame = findById(after.frames, id);
  if (frame == nullptr) return noSuch("frame", id);
  const app::EditorFrame old = *frame;
  frame->x = area.x;
  frame->y = area.y;
  frame->width = std::max(kMinFrameWidth, area.width);
  frame->height = std::max(kMinFrameHeight, area.height);
  if (old.x == frame->x && old.y == frame->y && old.width == frame->width &&
      old.height == frame->height)
    return makeError("unchanged");
  return Edit{"Resize frame", app, std::move(after)};
}

Result<Edit> moveFrame(const app::Application& app, std::string_view id, double dx, double dy) {
  if (dx == 0 && dy == 0) return makeError("unchanged");
  app::Application after = app;
  auto* frame = findById(after.frames, id);
  if (frame == nullptr) return noSuch("frame", id);
  // What lies inside is decided before the move, by each element's top-left corner.
  for (auto& node : after.editor) {
    if (inside(node.x, node.y, *frame)) {
      node.x += dx;
      node.y += dy;
    }
  }
  for (auto& note : after.notes) {
    if (inside(note.x, note.y, *frame)) {
      note.x += dx;
      note.y += dy;
    }
  }
  frame->x += dx;
  frame->y += dy;
  return Edit{"Move frame", app, std::move(after)};
}

Result<Edit> setFrameTitle(const app::Application& app, std::string_view id, std::string title) {
  return changeOne(app, &app::Application::frames, "frame", id, "Rename frame", [&](auto& frame) {
    if (frame.title == title) return false;
    frame.title = std::move(title);
    return true;
  });
}

Result<Edit> setFrameColor(const app::Application& app, std::string_view id, std::string color) {
  return changeOne(app, &app::Application::frames, "frame", id, "Recolour frame", [&](auto& frame) {
    if (frame.color == color) return false;
    frame.color = std::move(color);
    return true;
  });
}

Result<Edit> removeNotesAndFrames(const app::Application& app,
                                  const std::vector<std::string>& ids) {
  app::Application after = app;
  auto listed = [&](const auto& item) {
    return std::find(ids.begin(), ids.end(), item.id) != ids.end();
  };
  const std::size_t before = after.notes.size() + after.frames.size();
  std::erase_if(after.notes, listed);
  std::erase_if(after.frames, listed);
  if (after.notes.size() + after.frames.size() == before) return makeError("nothing to delete");
  return Edit{"Delete notes and frames", app, std::move(after)};
}

}  // namespace vrflow::editor
