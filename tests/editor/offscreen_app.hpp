#pragma once

// What every editor test suite starts with: one QApplication for the test program, on the
// offscreen platform unless QT_QPA_PLATFORM says otherwise.

#include <QApplication>
#include <QByteArray>

namespace vrflow::editor::gui {

/// Creates the program's QApplication (once), named `name`.
inline void startOffscreenApplication(const char* name) {
  if (qEnvironmentVariableIsEmpty("QT_QPA_PLATFORM")) qputenv("QT_QPA_PLATFORM", "offscreen");
  static int argc = 1;
  static QByteArray program(name);
  static char* argv[] = {program.data(), nullptr};
  if (QApplication::instance() == nullptr) new QApplication(argc, argv);
}

}  // namespace vrflow::editor::gui
