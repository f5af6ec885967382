#pragma once

// What the live view's and the timeline's tests share: the editor's window offscreen, and
// `vrflow` run from the build folder.
#include <gtest/gtest.h>

#include <QApplication>
#include <QFile>
#include <QProcess>
#include <QTemporaryDir>
#include <memory>

#include "main_window.hpp"
#include "offscreen_app.hpp"

namespace vrflow::editor::gui::testing {

inline QString sourceDir() {
  return QString(VRFLOW_TEST_SOURCE_DIR);
}

/// Answers the window's questions (the next file name) and records its errors.
class AnsweringReporter : public Reporter {
 public:
  void error(QWidget*, const QString& title, const QString& text) override {
    errors << title + ": " + text;
  }
  void warning(QWidget*, const QString&, const QString&) override {}
  QString fileName(QWidget*, bool, const QString&) override { return nextFile; }
  QStringList errors;
  QString nextFile;
};

class LiveWindow : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { startOffscreenApplication("vrflow_editor_live_tests"); }

  void SetUp() override {
    ASSERT_TRUE(dir_.isValid());
    EditorOptions options;
    options.settingsFile = dir_.filePath("settings.ini");
    options.reporter = &reporter_;
    options.rememberRecent = false;
    window_ = std::make_unique<MainWindow>(options);
    window_->resize(1400, 900);
    window_->show();
    QApplication::processEvents();
  }

  /// Runs `vrflow ARGS` in the test's folder; its exit status (-1: it did not end in 120 s).
  int vrflow(const QStringList& args) {
    QProcess process;
    process.setWorkingDirectory(dir_.path());
    process.setProcessChannelMode(QProcess::ForwardedChannels);
    process.start(QCoreApplication::applicationDirPath() + "/vrflow", args);
    if (!process.waitForFinished(120000)) {
      process.kill();
      process.waitForFinished();
      return -1;
    }
    return process.exitStatus() == QProcess::NormalExit ? process.exitCode() : -1;
  }

  /// The lines of a file.
  static QList<QByteArray> linesOf(const QString& path) {
    QFile file(path);
    if (!file.open(QIODevice::ReadOnly)) return {};
    QList<QByteArray> lines = file.readAll().split('\n');
    while (!lines.isEmpty() && lines.back().isEmpty()) lines.pop_back();
    return lines;
  }

  QTemporaryDir dir_;
  AnsweringReporter reporter_;
  std::unique_ptr<MainWindow> window_;
};

}  // namespace vrflow::editor::gui::testing
