#pragma once

#include <sys/types.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

// A real X server (Xvfb, Mesa's GLX) started by a test, with several screens, and what the
// on-screen tests need around it: processes in the background and input injected through XTest.

namespace vrflow::viewer::testing {

/// An Xvfb on display `:number`, stopped (by its pid) on destruction.
class Xvfb {
 public:
  /// Starts Xvfb with one screen per size (24-bit), waits until it accepts clients; nullopt
  /// with `why` set when it cannot (no Xvfb binary, the display taken, no answer in 10 s).
  static std::optional<Xvfb> start(int number, const std::vector<std::pair<int, int>>& screens,
                                   std::string& why);
  Xvfb(Xvfb&& other) noexcept;
  Xvfb& operator=(Xvfb&&) = delete;
  ~Xvfb();
  /// ":N.S"
  std::string display(int screen) const;

 private:
  Xvfb(pid_t pid, int number) : pid_(pid), number_(number) {}
  pid_t pid_ = 0;
  int number_ = 0;
};

/// A command running beside the test; killed (SIGKILL, by pid) and reaped on destruction if
/// still running.
class Background {
 public:
  explicit Background(const std::vector<std::string>& argv, const std::string& errFile);
  Background(const Background&) = delete;
  Background& operator=(const Background&) = delete;
  ~Background();
  /// Its exit status (128 + signal when killed), or nullopt when it still runs after `seconds`.
  std::optional<int> wait(double seconds);
  /// Sends `signal` to it (if it still runs).
  void signal(int signal);
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = 0;
};

/// Runs xdotool with `args` on `display`; its exit status.
int xdotool(const std::string& display, const std::vector<std::string>& args);

}  // namespace vrflow::viewer::testing
