#pragma once

#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/message/input_events.hpp"

// An on-screen window on an X display and screen, through GLFW (GLX): the second context the
// renderer draws into, and the source of a tile's keyboard and mouse events.

namespace vrflow::viewer {

/// Where and how a window opens.
struct WindowSettings {
  std::string display;  ///< X display and screen, e.g. ":0.1"; empty: the DISPLAY variable
  int width = 960;      ///< client area (pixels)
  int height = 540;
  bool fullScreen = false;  ///< on the screen's monitor, at its mode closest to width x height
  int x = 0;                ///< placed (not full screen): top-left corner on the screen (pixels)
  int y = 0;
  std::string title = "vrflow";
};

/// A pointer or key event of a window, in window pixels; a pointer event's world ray is left
/// empty (the viewer fills it from its tile's camera).
using WindowEvent = std::variant<msg::PointerEvent, msg::KeyEvent>;

/// A double-buffered RGBA window with 24-bit depth and 8-bit stencil, OpenGL 2.1 compatibility.
/// One per process; it must outlive the Renderer drawing into it.
class Window {
 public:
  /// Opens the window; an error names the display and what GLFW said.
  static Result<Window> open(const WindowSettings& settings);
  Window(Window&&) noexcept;
  Window& operator=(Window&&) noexcept;
  ~Window();

  /// Makes the window's context current on this thread.
  void makeCurrent();
  /// Shows the back buffer (no wait for the vertical retrace).
  void swap();
  /// Handles pending window-system events and returns the pointer and key events since the
  /// last call, in order.
  std::vector<WindowEvent> poll();
  /// True once the user asked to close the window.
  bool closeRequested() const;
  /// The client area's size in pixels.
  int width() const;
  int height() const;

 private:
  struct Impl;
  explicit Window(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace vrflow::viewer
