// The canvas' notes and frames: their items kept in step with the application, the edits a
// drag, a resize, an in-place text or the context menu make of them.
#include <QAction>
#include <QGraphicsScene>
#include <QMenu>
#include <QPointer>

#include "canvas.hpp"
#include "qt_text.hpp"
#include "vrflow/editor/notes.hpp"

namespace vrflow::editor::gui {

namespace {

// The colours a frame can be given from its menu.
const std::pair<const char*, const char*> kFrameColors[] = {
    {"Blue", "#7890b4"}, {"Green", "#4caf50"},  {"Orange", "#e08a1e"},
    {"Red", "#d9534f"},  {"Purple", "#9c27b0"}, {"Grey", "#8a8f99"}};

Rect areaOf(const QGraphicsItem* item, QSizeF size) {
  return {item->pos().x(), item->pos().y(), size.width(), size.height()};
}

}  // namespace

NoteItem* Canvas::noteItem(const std::string& id) const {
  auto it = notes_.find(id);
  return it == notes_.end() ? nullptr : it->second;
}

FrameItem* Canvas::frameItem(const std::string& id) const {
  auto it = frames_.find(id);
  return it == frames_.end() ? nullptr : it->second;
}

std::vector<std::string> Canvas::selectedNotesAndFrames() const {
  std::vector<std::string> ids;
  for (const auto& [id, item] : notes_) {
    if (item->isSelected()) ids.push_back(id);
  }
  for (const auto& [id, item] : frames_) {
    if (item->isSelected()) ids.push_back(id);
  }
  return ids;
}

void Canvas::requestEdit(Result<Edit> edit) {
  if (edit) Q_EMIT editRequested(*edit);
}

void Canvas::syncNotesAndFrames() {
  const app::Application& app = *state_.app;
  QPointer<Canvas> self(this);
  std::map<std::string, NoteItem*> notes;
  for (const auto& note : app.notes) {
    NoteItem* item = noteItem(note.id);
    if (item == nullptr) {
      item = new NoteItem(note.id, QSizeF(note.width, note.height), qtText(note.text));
      item->textEdited = [self](const std::string& id, const QString& text) {
        if (self) self->requestEdit(setNoteText(*self->state_.app, id, stdText(text)));
      };
      scene_->addItem(item);
    }
    notes_.erase(note.id);
    if (item->pos() != QPointF(note.x, note.y)) item->setPos(note.x, note.y);
    item->setSize(QSizeF(note.width, note.height));
    if (item->text() != qtText(note.text)) item->setText(qtText(note.text));
    notes[note.id] = item;
  }
  for (auto& [id, item] : notes_) delete item;
  notes_ = std::move(notes);

  std::map<std::string, FrameItem*> frames;
  for (const auto& frame : app.frames) {
    FrameItem* item = frameItem(frame.id);
    if (item == nullptr) {
      item = new FrameItem(frame.id, QSizeF(frame.width, frame.height), qtText(frame.title),
                           colorOfFrame(frame.color));
      item->titleEdited = [self](const std::string& id, const QString& title) {
        if (self) self->requestEdit(setFrameTitle(*self->state_.app, id, stdText(title)));
      };
      scene_->addItem(item);
    }
    frames_.erase(frame.id);
    if (item->pos() != QPointF(frame.x, frame.y)) item->setPos(frame.x, frame.y);
    item->setSize(QSizeF(frame.width, frame.height));
    item->setTitle(qtText(frame.title));
    item->setColor(colorOfFrame(frame.color));
    frames[frame.id] = item;
  }
  for (auto& [id, item] : frames_) delete item;
  frames_ = std::move(frames);
}

void Canvas::reportNoteAndFrameChanges() {
  if (state_.app == nullptr) return;
  const app::Application& app = *state_.app;
  for (const auto& note : app.notes) {
    const NoteItem* item = noteItem(note.id);
    if (item == nullptr) continue;
    const Rect now = areaOf(item, item->size());
    if (now.x != note.x || now.y != note.y || now.width != note.width || now.height != note.height)
      return requestEdit(setNoteArea(app, note.id, now));
  }
  for (const auto& frame : app.frames) {
    const FrameItem* item = frameItem(frame.id);
    if (item == nullptr) continue;
    if (item->size() != QSizeF(frame.width, frame.height))
      return requestEdit(setFrameArea(app, frame.id, areaOf(item, item->size())));
    if (item->pos() != QPointF(frame.x, frame.y)) {
      return requestEdit(
          moveFrame(app, frame.id, item->pos().x() - frame.x, item->pos().y() - frame.y));
    }
  }
}

void Canvas::addFrameAroundSelection() {
  QRectF area;
  for (const auto& id : selectedNodes()) area = area.united(nodeItem(id)->sceneBody());
  for (const auto& [id, note] : notes_) {
    if (note->isSelected()) area = area.united(note->sceneBoundingRect());
  }
  if (area.isNull()) return;
  // Room for the title above and a margin around (the nodes' top-left corners fall inside).
  area = area.adjusted(-30, -50, 30, 40);
  requestEdit(addFrame(*state_.app, {area.x(), area.y(), area.width(), area.height()}, "Group"));
}

QMenu* Canvas::frameMenu(FrameItem* frame) {
  auto* menu = new QMenu(this);
  const std::string id = frame->id();
  menu->addAction("Rename frame", this, [this, id] {
    if (auto* item = frameItem(id)) item->editTitle();
  });
  QMenu* colors = menu->addMenu("Frame colour");
  for (const auto& [name, value] : kFrameColors) {
    colors->addAction(name, this, [this, id, color = std::string(value)] {
      requestEdit(setFrameColor(*state_.app, id, color));
    });
  }
  menu->addAction("Delete frame", this,
                  [this, id] { requestEdit(removeNotesAndFrames(*state_.app, {id})); });
  return menu;
}

QMenu* Canvas::contextMenuAt(QPoint viewPos) {
  if (state_.app == nullptr || nodeAt(viewPos) != nullptr) return nullptr;
  for (QGraphicsItem* item : items(viewPos)) {
    if (auto* note = dynamic_cast<NoteItem*>(item)) {
      auto* menu = new QMenu(this);
      const std::string id = note->id();
      menu->addAction("Edit note", this, [this, id] {
        if (auto* n = noteItem(id)) n->editText();
      });
      menu->addAction("Delete note", this,
                      [this, id] { requestEdit(removeNotesAndFrames(*state_.app, {id})); });
      return menu;
    }
  }
  if (FrameItem* frame = frameAt(viewPos)) return frameMenu(frame);
  auto* menu = new QMenu(this);
  const QPointF at = mapToScene(viewPos);
  menu->addAction("Add note", this,
                  [this, at] { requestEdit(addNote(*state_.app, at.x(), at.y(), "Note")); });
  menu->addAction("Add frame", this, [this, at] {
    requestEdit(addFrame(*state_.app, {at.x(), at.y(), 400, 300}, "Group"));
  });
  QAction* around =
      menu->addAction("Frame around selection", this, [this] { addFrameAroundSelection(); });
  around->setEnabled(!selectedNodes().empty());
  return menu;
}

FrameItem* Canvas::frameAt(QPoint viewPos) const {
  for (QGraphicsItem* item : items(viewPos)) {
    if (auto* frame = dynamic_cast<FrameItem*>(item)) return frame;
  }
  return nullptr;
}

}  // namespace vrflow::editor::gui
