#pragma once

// Edits of the canvas' notes and frames (`<note>` and `<frame>` in the `<editor>` section): each
// one an undoable Edit, like the edits of edit.hpp.

#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/editor/edit.hpp"

namespace vrflow::editor {

/// A rectangle in scene units (top-left corner, size).
struct Rect {
  double x = 0;
  double y = 0;
  double width = 0;
  double height = 0;
};

/// Adds a note at (x, y) with `text`; its id ("note", "note2", ...) goes to `newId`.
Result<Edit> addNote(const app::Application& app, double x, double y, std::string text,
                     std::string* newId = nullptr);
/// Adds a frame titled `title` over `area`; its id ("frame", "frame2", ...) goes to `newId`.
Result<Edit> addFrame(const app::Application& app, Rect area, std::string title,
                      std::string* newId = nullptr);
/// Moves and resizes a note (sizes below 40 x 24 are raised to it).
Result<Edit> setNoteArea(const app::Application& app, std::string_view id, Rect area);
/// Replaces a note's text.
Result<Edit> setNoteText(const app::Application& app, std::string_view id, std::string text);
/// Resizes a frame in place (sizes below 80 x 50 are raised to it); nothing else moves.
Result<Edit> setFrameArea(const app::Application& app, std::string_view id, Rect area);
/// Moves a frame by (dx, dy) with the nodes and notes whose top-left corner lies inside it.
Result<Edit> moveFrame(const app::Application& app, std::string_view id, double dx, double dy);
/// Renames a frame.
Result<Edit> setFrameTitle(const app::Application& app, std::string_view id, std::string title);
/// Recolours a frame ("#rrggbb", or empty for the default colour).
Result<Edit> setFrameColor(const app::Application& app, std::string_view id, std::string color);
/// Removes notes and frames by id.
Result<Edit> removeNotesAndFrames(const app::Application& app, const std::vector<std::string>& ids);

/// The note with this id, or nullptr.
const app::EditorNote* findNote(const app::Application& app, std::string_view id);
/// The frame with this id, or nullptr.
const app::EditorFrame* findFrame(const app::Application& app, std::string_view id);

}  // namespace vrflow::editor
