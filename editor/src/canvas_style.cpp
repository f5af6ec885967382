#include "canvas_style.hpp"

#include <functional>

namespace vrflow::editor::gui {

QColor colorOfData(const std::string& data) {
  if (data == "any" || data.empty()) return QColor(120, 120, 130);
  if (data == "objects") return QColor(52, 120, 246);
  if (data == "events") return QColor(236, 130, 30);
  if (data == "resources") return QColor(40, 170, 90);
  std::size_t hash = std::hash<std::string>{}(data);
  return QColor::fromHsv(static_cast<int>(hash % 360), 170, 210);
}

QColor colorOfHost(std::size_t index) {
  static const QColor colors[] = {QColor(96, 125, 139), QColor(0, 150, 136), QColor(156, 39, 176),
                                  QColor(233, 30, 99),  QColor(63, 81, 181), QColor(205, 140, 0),
                                  QColor(121, 85, 72),  QColor(76, 175, 80)};
  return colors[index % (sizeof colors / sizeof colors[0])];
}

QColor colorOfFrame(const std::string& color) {
  const QColor parsed = QColor::fromString(color);
  return parsed.isValid() ? parsed : QColor(120, 144, 180);
}

}  // namespace vrflow::editor::gui
