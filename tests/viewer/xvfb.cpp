#include "xvfb.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "../runtime/process_helpers.hpp"

namespace vrflow::viewer::testing {
namespace {

pid_t spawn(const std::vector<std::string>& argv, const std::string& errFile) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int out =
        open(errFile.empty() ? "/dev/null" : errFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (out >= 0) {
      dup2(out, 1);
      dup2(out, 2);
    }
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    _exit(127);
  }
  return pid;
}

std::optional<int> waitFor(pid_t pid, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (;;) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    if (std::chrono::steady_clock::now() >= end) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

}  // namespace

std::optional<Xvfb> Xvfb::start(int number, const std::vector<std::pair<int, int>>& screens,
                                std::string& why) {
  if (vrflow::testing::runCommand({"/bin/sh", "-c", "command -v Xvfb"}, 10).exitCode != 0) {
    why = "Xvfb is not installed (Debian package xvfb)";
    return std::nullopt;
  }
  if (vrflow::testing::runCommand({"/bin/sh", "-c", "command -v xdotool"}, 10).exitCode != 0) {
    why = "xdotool is not installed (Debian package xdotool)";
    return std::nullopt;
  }
  const std::string socket = "/tmp/.X11-unix/X" + std::to_string(number);
  if (std::filesystem::exists(socket) ||
      std::filesystem::exists("/tmp/.X" + std::to_string(number) + "-lock")) {
    why = "display :" + std::to_string(number) + " is taken";
    return std::nullopt;
  }
  std::vector<std::string> argv{"Xvfb", ":" + std::to_string(number), "-nolisten", "tcp"};
  for (std::size_t s = 0; s < screens.size(); ++s) {
    argv.insert(argv.end(), {"-screen", std::to_string(s),
                             std::to_string(screens[s].first) + "x" +
                                 std::to_string(screens[s].second) + "x24"});
  }
  Xvfb server(spawn(argv, ""), number);
  for (int tries = 0; tries < 1000; ++tries) {
    if (waitFor(server.pid_, 0.0)) {
      server.pid_ = 0;
      why = "Xvfb :" + std::to_string(number) + " exited at start";
      return std::nullopt;
    }
    // Ready once a client can connect and query it.
    if (std::filesystem::exists(socket) &&
        xdotool(server.display(0), {"getdisplaygeometry"}) == 0) {
      return server;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  why = "Xvfb :" + std::to_string(number) + " did not accept clients within 10 s";
  return std::nullopt;
}

Xvfb::Xvfb(Xvfb&& other) noexcept : pid_(other.pid_), number_(other.number_) {
  other.pid_ = 0;
}

Xvfb::~Xvfb() {
  if (pid_ <= 0) return;
  kill(pid_, SIGTERM);
  if (!waitFor(pid_, 5.0)) {
    kill(pid_, SIGKILL);
    waitFor(pid_, 5.0);
  }
}

std::string Xvfb::display(int screen) const {
  return ":" + std::to_string(number_) + "." + std::to_string(screen);
}

Background::Background(const std::vector<std::string>& argv, const std::string& errFile)
    : pid_(spawn(argv, errFile)) {}

Background::~Background() {
  if (pid_ <= 0) return;
  kill(pid_, SIGKILL);
  waitFor(pid_, 10.0);
}

std::optional<int> Background::wait(double seconds) {
  if (pid_ <= 0) return std::nullopt;
  auto status = waitFor(pid_, seconds);
  if (status) pid_ = 0;
  return status;
}

void Background::signal(int signal) {
  if (pid_ > 0) kill(pid_, signal);
}

int xdotool(const std::string& display, const std::vector<std::string>& args) {
  std::vector<std::string> argv{"/usr/bin/env", "DISPLAY=" + display, "xdotool"};
  argv.insert(argv.end(), args.begin(), args.end());
  return vrflow::testing::runCommand(argv, 20).exitCode;
}

}  // namespace vrflow::viewer::testing
