// The canvas's wall view: a node that names a wall file opens as the wall (wall_view.hpp).
#include <filesystem>

#include "canvas.hpp"
#include "qt_text.hpp"
#include "wall_view.hpp"

namespace vrflow::editor::gui {

std::string Canvas::wallFileOf(const std::string& id) const {
  if (state_.app == nullptr) return {};
  const std::vector<app::Param>* params = nullptr;
  if (const app::Instance* instance = app::findInstance(*state_.app, id)) {
    params = &instance->params;
  } else if (const app::Module* module = app::findModule(*state_.app, id)) {
    params = &module->params;
  }
  const std::string file = params ? app::paramString(*params, "wall", "") : std::string();
  if (file.empty() || file.find("${") != std::string::npos) return {};
  // Relative to the application's folder, as the runtime resolves a file parameter.
  const std::filesystem::path path(file);
  if (path.is_absolute() || state_.app->file.empty()) return file;
  return (std::filesystem::path(state_.app->file).parent_path() / path).lexically_normal();
}

bool Canvas::openWall(const std::string& id) {
  const std::string file = wallFileOf(id);
  if (file.empty()) {
    lastRefusal_ = "'" + qtText(id) + "' names no wall file (parameter 'wall')";
    Q_EMIT messageRequested(lastRefusal_);
    return false;
  }
  auto wall = viewer::loadWall(file);
  if (!wall) {
    lastRefusal_ = "Cannot show the wall of '" + qtText(id) + "': " + qtText(wall.error().message);
    Q_EMIT messageRequested(lastRefusal_);
    return false;
  }
  closeWall();
  const QString path =
      qtText(state_.app->name.empty() ? std::string("application") : state_.app->name) +
      "  \u203A  " + qtText(id) + " (wall " +
      qtText(std::filesystem::path(file).filename().string()) + ": " + WallView::describe(*wall) +
      ")";
  wallView_ = new WallView(this, std::move(*wall), *state_.app, path);
  connect(wallView_, &WallView::closeRequested, this, &Canvas::closeWall);
  return true;
}

void Canvas::closeWall() {
  if (wallView_ == nullptr) return;
  wallView_->hide();
  wallView_->deleteLater();
  wallView_ = nullptr;
  setFocus();
}

}  // namespace vrflow::editor::gui
