#pragma once

// What every editor test suite starts with: one QApplication for the test program, on the
// offscreen platform unless QT_QPA_PLATFORM says otherwise; and the real mouse events the
// suites send to a view.

#include <QAbstractScrollArea>
#include <QApplication>
#include <QByteArray>
#include <QMouseEvent>

namespace vrflow::editor::gui {

/// Creates the program's QApplication (once), named `name`.
inline void startOffscreenApplication(const char* name) {
  if (qEnvironmentVariableIsEmpty("QT_QPA_PLATFORM")) qputenv("QT_QPA_PLATFORM", "offscreen");
  static int argc = 1;
  static QByteArray program(name);
  static char* argv[] = {program.data(), nullptr};
  if (QApplication::instance() == nullptr) new QApplication(argc, argv);
}

/// Sends one real mouse event at `pos` (viewport coordinates) to `view`'s viewport.
inline void sendMouse(QAbstractScrollArea* view, QEvent::Type type, QPoint pos,
                      Qt::MouseButton button, Qt::MouseButtons buttons) {
  QWidget* viewport = view->viewport();
  QMouseEvent event(type, QPointF(pos), viewport->mapToGlobal(QPointF(pos)), button, buttons,
                    Qt::NoModifier);
  QApplication::sendEvent(viewport, &event);
}

}  // namespace vrflow::editor::gui
