#pragma once

// Text between the model (std::string) and Qt (QString), for the editor's widgets.

#include <QString>
#include <string>

namespace vrflow::editor::gui {

/// A model's text as Qt text.
inline QString qtText(const std::string& text) {
  return QString::fromStdString(text);
}

/// Qt text as a model's text.
inline std::string stdText(const QString& text) {
  return text.toStdString();
}

}  // namespace vrflow::editor::gui
