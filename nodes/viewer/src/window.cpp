#include "vrflow/viewer/window.hpp"

#include <GLFW/glfw3.h>

#include <cstdlib>
#include <ctime>

namespace vrflow::viewer {
namespace {

// GLFW reports errors through a callback; the last one is kept for the next error message.
std::string& lastGlfwError() {
  static std::string text;
  return text;
}

void onGlfwError(int code, const char* description) {
  lastGlfwError() =
      std::string(description ? description : "?") + " (GLFW error " + std::to_string(code) + ")";
}

double now() {
  timespec t{};
  clock_gettime(CLOCK_REALTIME, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

struct Window::Impl {
  GLFWwindow* window = nullptr;
  std::vector<WindowEvent> events;
  std::uint32_t buttons = 0;  // buttonBit()s held
  double x = 0.0, y = 0.0;    // the pointer's last position

  ~Impl() {
    if (window) glfwDestroyWindow(window);
    glfwTerminate();
  }

  static Impl& of(GLFWwindow* w) { return *static_cast<Impl*>(glfwGetWindowUserPointer(w)); }

  msg::PointerEvent pointer(msg::PointerAction action, int mods) const {
    msg::PointerEvent e;
    e.action = action;
    e.buttons = buttons;
    e.modifiers = static_cast<std::uint32_t>(mods);
    e.x = x;
    e.y = y;
    e.time = now();
    return e;
  }
};

Window::Window(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Window::Window(Window&&) noexcept = default;
Window& Window::operator=(Window&&) noexcept = default;
Window::~Window() = default;

Result<Window> Window::open(const WindowSettings& settings) {
  // GLFW's X11 back end connects to $DISPLAY (its screen part picks the screen).
  if (!settings.display.empty()) setenv("DISPLAY", settings.display.c_str(), 1);
  const char* display = std::getenv("DISPLAY");
  const std::string where = display ? std::string("display '") + display + "'" : "no DISPLAY";
  glfwSetErrorCallback(onGlfwError);
  lastGlfwError().clear();
  if (!glfwInit()) {
    return makeError("cannot open a window on " + where + ": " + lastGlfwError());
  }
  auto impl = std::make_unique<Impl>();
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_NATIVE_CONTEXT_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 2);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
  glfwWindowHint(GLFW_RED_BITS, 8);
  glfwWindowHint(GLFW_GREEN_BITS, 8);
  glfwWindowHint(GLFW_BLUE_BITS, 8);
  glfwWindowHint(GLFW_ALPHA_BITS, 8);
  glfwWindowHint(GLFW_DEPTH_BITS, 24);
  glfwWindowHint(GLFW_STENCIL_BITS, 8);
  glfwWindowHint(GLFW_DOUBLEBUFFER, GLFW_TRUE);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
  glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);  // shown once placed
  GLFWmonitor* monitor = settings.fullScreen ? glfwGetPrimaryMonitor() : nullptr;
  if (settings.fullScreen && !monitor) {
    return makeError("cannot open a full-screen window on " + where + ": no monitor found (" +
                     lastGlfwError() + ")");
  }
  impl->window =
      glfwCreateWindow(settings.width, settings.height, settings.title.c_str(), monitor, nullptr);
  if (!impl->window) {
    return makeError("cannot open a " + std::to_string(settings.width) + "x" +
                     std::to_string(settings.height) + " OpenGL window on " + where + ": " +
                     lastGlfwError());
  }
  if (!monitor) glfwSetWindowPos(impl->window, settings.x, settings.y);
  glfwShowWindow(impl->window);
  glfwMakeContextCurrent(impl->window);
  glfwSwapInterval(0);
  glfwSetWindowUserPointer(impl->window, impl.get());
  glfwSetCursorPosCallback(impl->window, [](GLFWwindow* w, double x, double y) {
    Impl& self = Impl::of(w);
    self.x = x;
    self.y = y;
    self.events.emplace_back(self.pointer(msg::PointerAction::Move, 0));
  });
  glfwSetMouseButtonCallback(impl->window, [](GLFWwindow* w, int button, int action, int mods) {
    Impl& self = Impl::of(w);
    if (button > GLFW_MOUSE_BUTTON_MIDDLE) return;  // the contract names three buttons
    const auto b = static_cast<msg::PointerButton>(button);
    if (action == GLFW_PRESS) {
      self.buttons |= msg::buttonBit(b);
    } else {
      self.buttons &= ~msg::buttonBit(b);
    }
    auto e = self.pointer(
        action == GLFW_PRESS ? msg::PointerAction::Press : msg::PointerAction::Release, mods);
    e.button = b;
    self.events.emplace_back(e);
  });
  glfwSetScrollCallback(impl->window, [](GLFWwindow* w, double, double dy) {
    Impl& self = Impl::of(w);
    auto e = self.pointer(msg::PointerAction::Scroll, 0);
    e.scroll = dy;
    self.events.emplace_back(e);
  });
  glfwSetKeyCallback(impl->window, [](GLFWwindow* w, int key, int, int action, int mods) {
    msg::KeyEvent e;
    e.key = key;
    e.action = action == GLFW_PRESS    ? msg::KeyAction::Press
               : action == GLFW_REPEAT ? msg::KeyAction::Repeat
                                       : msg::KeyAction::Release;
    e.modifiers = static_cast<std::uint32_t>(mods);
    e.time = now();
    Impl::of(w).events.emplace_back(e);
  });
  return Window(std::move(impl));
}

void Window::makeCurrent() {
  glfwMakeContextCurrent(impl_->window);
}

void Window::swap() {
  glfwSwapBuffers(impl_->window);
}

std::vector<WindowEvent> Window::poll() {
  glfwPollEvents();
  std::vector<WindowEvent> out;
  out.swap(impl_->events);
  return out;
}

bool Window::closeRequested() const {
  return glfwWindowShouldClose(impl_->window) != 0;
}

int Window::width() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(impl_->window, &w, &h);
  return w;
}

int Window::height() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(impl_->window, &w, &h);
  return h;
}

}  // namespace vrflow::viewer
