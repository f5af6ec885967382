#pragma once

// The colours the canvas draws data types and hosts in.

#include <QColor>
#include <cstddef>
#include <string>

namespace vrflow::editor::gui {

/// The colour of a message data type ("objects", "events", ..., "any").
QColor colorOfData(const std::string& data);
/// The colour of the host at `index` in the application's host list.
QColor colorOfHost(std::size_t index);
/// The colour of a frame: `color` ("#rrggbb") when valid, else the default frame colour.
QColor colorOfFrame(const std::string& color);

}  // namespace vrflow::editor::gui
