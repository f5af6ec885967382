// The editor window's document: new, open, save, recent files, the title, closing.
#include <QCloseEvent>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QMenu>
#include <QPlainTextEdit>
#include <QSaveFile>
#include <QSettings>
#include <QShowEvent>
#include <QStatusBar>
#include <QUndoStack>
#include <algorithm>

#include "main_window.hpp"
#include "vrflow/app/catalog.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/writer.hpp"

namespace vrflow::editor::gui {
namespace {

constexpr int kMaxRecent = 8;

std::string toStd(const QString& text) {
  return text.toStdString();
}

}  // namespace

// ---- File --------------------------------------------------------------------------------

void MainWindow::setDocument(app::Application app, OpenedText opened, const QString& path) {
  app_ = std::move(app);
  opened_ = std::move(opened);
  path_ = path;
  lastRun_.reset();
  // Not blocked: the Undo and Redo actions follow the stack's signals, and must forget the
  // previous document's edits.
  undo_->clear();
  undo_->setClean();
  computeFallbackLayout();
  refresh();
  canvas_->fitAll();
  updateTitle();
}

void MainWindow::newFile() {
  app::Application app;
  app.name = "untitled";
  app.hosts.push_back(
      {std::string(app::kDefaultHostId), std::string(app::kDefaultHostAddress), {}});
  setDocument(std::move(app), OpenedText{}, QString());
}

bool MainWindow::openFile(const QString& path) {
  QFile in(path);
  if (!in.open(QIODevice::ReadOnly)) {
    reporter().error(this, "Cannot open file", "Cannot read " + path + ": " + in.errorString());
    return false;
  }
  const std::string text = in.readAll().toStdString();
  std::vector<app::Diagnostic> problems;
  const std::string absolute = toStd(QFileInfo(path).absoluteFilePath());
  auto loaded = app::loadApplicationString(text, absolute, &problems);
  // Not well-formed, or not an application at all (a manifest, a composite): nothing to edit.
  const bool notAnApplication = std::any_of(
      problems.begin(), problems.end(),
      [](const app::Diagnostic& d) { return d.message.rfind("root element must be", 0) == 0; });
  if (!loaded || notAnApplication) {
    reporter().error(this, "Cannot open file",
                     QFileInfo(path).fileName() + " is not a valid vrflow application file:\n\n" +
                         (loaded ? QString::fromStdString(app::formatDiagnostics(problems))
                                 : QString::fromStdString(loaded.error().message)));
    return false;
  }
  addPackageFolders(*loaded);
  OpenedText opened{text, app::saveApplication(*loaded)};
  setDocument(std::move(*loaded), std::move(opened), QFileInfo(path).absoluteFilePath());
  addRecent(path_);
  log_->appendPlainText("Opened " + path_);
  if (!problems.empty()) {
    reporter().warning(this, "Problems in " + QFileInfo(path).fileName(),
                       "What could be read was loaded; saving writes it without these:\n\n" +
                           QString::fromStdString(app::formatDiagnostics(problems)));
  }
  return true;
}

// The file's <packages> folders join the palette, after the folders the editor started with.
void MainWindow::addPackageFolders(const app::Application& app) {
  std::vector<app::Diagnostic> missing;
  const std::vector<std::string> folders = app::packageFolders(app, missing);
  for (const app::Diagnostic& problem : missing) {
    log_->appendPlainText(QString::fromStdString(app::formatDiagnostic(problem)));
  }
  if (folders.empty()) return;
  if (const Status loaded = catalog_->loadSearchPath(folders); !loaded) {
    log_->appendPlainText("Node packages: " + QString::fromStdString(loaded.error().message));
  }
  palette_->setCatalog(*catalog_);
}

bool MainWindow::save() {
  if (path_.isEmpty()) {
    const QString path = reporter().fileName(
        this, true, QDir::currentPath() + "/" + QString::fromStdString(app_.name) + ".xml");
    if (path.isEmpty()) return false;
    return saveAs(path);
  }
  return saveAs(path_);
}

bool MainWindow::saveAs(const QString& path) {
  const std::string text = textToSave(app_, opened_);
  QSaveFile out(path);
  if (!out.open(QIODevice::WriteOnly) ||
      out.write(text.data(), static_cast<qint64>(text.size())) < 0 || !out.commit()) {
    reporter().error(this, "Cannot save", "Cannot write " + path + ": " + out.errorString());
    return false;
  }
  opened_ = OpenedText{text, app::saveApplication(app_)};
  path_ = QFileInfo(path).absoluteFilePath();
  app_.file = toStd(path_);
  undo_->setClean();
  addRecent(path_);
  statusBar()->showMessage("Saved " + path_, 5000);
  refresh();
  return true;
}

bool MainWindow::modified() const {
  return !undo_->isClean();
}

bool MainWindow::maybeSave() {
  if (!modified()) return true;
  switch (reporter().askToSave(this, "The application \"" + QString::fromStdString(app_.name) +
                                         "\" has unsaved changes. Save them?")) {
    case Reporter::Choice::Save:
      return save();
    case Reporter::Choice::Discard:
      return true;
    case Reporter::Choice::Cancel:
      break;
  }
  return false;
}

QStringList MainWindow::recentFiles() const {
  return settings_->value("recentFiles").toStringList();
}

void MainWindow::addRecent(const QString& path) {
  if (!options_.rememberRecent) return;
  QStringList files = recentFiles();
  files.removeAll(path);
  files.prepend(path);
  while (files.size() > kMaxRecent) files.removeLast();
  settings_->setValue("recentFiles", files);
  rebuildRecentMenu();
}

void MainWindow::rebuildRecentMenu() {
  if (recentMenu_ == nullptr) return;
  recentMenu_->clear();
  for (const QString& file : recentFiles()) {
    recentMenu_->addAction(file, this, [this, file] {
      if (maybeSave()) openFile(file);
    });
  }
  recentMenu_->setEnabled(!recentMenu_->isEmpty());
}

void MainWindow::updateTitle() {
  const QString name = path_.isEmpty() ? QString("untitled") : QFileInfo(path_).fileName();
  setWindowTitle(name + "[*] \u2014 " + QString::fromStdString(app_.name) +
                 " \u2014 vrflow editor");
  setWindowModified(modified());
}

void MainWindow::showEvent(QShowEvent* event) {
  QMainWindow::showEvent(event);
  if (shown_) return;
  shown_ = true;
  // Dock sizes apply once the window has its size.
  resizeDocks({paletteDock_, propertiesDock_}, {190, 330}, Qt::Horizontal);
  resizeDocks({propertiesDock_, hostsDock_}, {height() * 2 / 5, height() / 5}, Qt::Vertical);
}

void MainWindow::closeEvent(QCloseEvent* event) {
  if (!maybeSave()) {
    event->ignore();
    return;
  }
  stopRun();
  event->accept();
}

}  // namespace vrflow::editor::gui
