#include "vrflow/run/progress.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <mutex>

namespace vrflow::run {
namespace {

// The live line on the terminal, shared with printAboveProgress(): the text to redraw (empty
// when none shows), under its lock with every write of either.
std::mutex& liveMutex() {
  static std::mutex mutex;
  return mutex;
}
std::string& liveLine() {
  static std::string line;
  return line;
}

// "37s", "2m05s", "1h02m".
std::string duration(double seconds) {
  const auto s = static_cast<long long>(seconds + 0.5);
  char text[48];
  if (s < 60) {
    std::snprintf(text, sizeof text, "%llds", s);
  } else if (s < 3600) {
    std::snprintf(text, sizeof text, "%lldm%02llds", s / 60, s % 60);
  } else {
    std::snprintf(text, sizeof text, "%lldh%02lldm", s / 3600, (s % 3600) / 60);
  }
  return text;
}

// Writes the live line (cut to the terminal's width); the caller holds liveMutex().
void drawLocked(const std::string& text) {
  std::string line = text;
  winsize ws{};
  if (ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 10 && line.size() >= ws.ws_col) {
    line.resize(ws.ws_col - 1u);  // the cursor stays on the line: no wrap
  }
  std::fputs(("\r" + line + "\033[K").c_str(), stderr);
  std::fflush(stderr);
  liveLine() = line;
}

}  // namespace

uint64_t outerIterationsDone(const std::vector<ModuleProgress>& modules, uint64_t outer) {
  uint64_t least = std::numeric_limits<uint64_t>::max();
  bool counted = false;
  for (const auto& m : modules) {
    if (outer > 0 && m.target == 0) continue;
    uint64_t done = m.done;
    if (outer > 0) {
      const unsigned __int128 share = static_cast<unsigned __int128>(m.done) * outer / m.target;
      done = static_cast<uint64_t>(std::min<unsigned __int128>(share, outer));
    }
    least = std::min(least, done);
    counted = true;
  }
  if (!counted && outer > 0) return outerIterationsDone(modules, 0);
  return counted ? least : 0;
}

ProgressLine::ProgressLine(ProgressMode mode, uint64_t outer)
    : mode_(mode), outer_(outer), start_(Clock::now()), lastDraw_(start_) {}

ProgressLine::~ProgressLine() {
  if (mode_ != ProgressMode::Live || finished_) return;
  const std::lock_guard lock(liveMutex());
  if (!liveLine().empty()) std::fputs("\n", stderr);  // leave the last line as it was
  liveLine().clear();
}

std::string ProgressLine::liveText(uint64_t done, double seconds) {
  char text[256];
  if (outer_ > 0) {
    const double percent = 100.0 * static_cast<double>(done) / static_cast<double>(outer_);
    std::string left = "?";
    if (rate_ > 0) left = duration(static_cast<double>(outer_ - std::min(done, outer_)) / rate_);
    std::snprintf(text, sizeof text,
                  "[vrflow %s] %llu/%llu iterations (%.0f%%), %.1f it/s, %s left",
                  duration(seconds).c_str(), static_cast<unsigned long long>(done),
                  static_cast<unsigned long long>(outer_), percent, rate_, left.c_str());
  } else {
    std::snprintf(text, sizeof text, "[vrflow %s] %llu iterations, %.1f it/s",
                  duration(seconds).c_str(), static_cast<unsigned long long>(done), rate_);
  }
  return text;
}

bool ProgressLine::due() const {
  return mode_ == ProgressMode::Live && !finished_ &&
         std::chrono::duration<double>(Clock::now() - lastDraw_).count() >= 1.0;
}

void ProgressLine::update(uint64_t done) {
  if (!due()) return;
  const auto now = Clock::now();
  const double dt = std::chrono::duration<double>(now - lastDraw_).count();
  const double instant = static_cast<double>(done - std::min(done, lastDone_)) / dt;
  rate_ = rate_ == 0 ? instant : 0.7 * rate_ + 0.3 * instant;  // steadier time left
  lastDone_ = done;
  lastDraw_ = now;
  const std::string text = liveText(done, std::chrono::duration<double>(now - start_).count());
  const std::lock_guard lock(liveMutex());
  drawLocked(text);
}

void ProgressLine::finish(uint64_t done, std::string_view status) {
  if (mode_ == ProgressMode::Off || finished_) return;
  finished_ = true;
  const double seconds = std::chrono::duration<double>(Clock::now() - start_).count();
  const double rate = seconds > 0 ? static_cast<double>(done) / seconds : 0.0;
  char text[256];
  std::snprintf(text, sizeof text, "vrflow: %llu%s%s iterations in %.1f s (%.1f it/s), status %.*s",
                static_cast<unsigned long long>(done), outer_ > 0 ? " of " : "",
                outer_ > 0 ? std::to_string(outer_).c_str() : "", seconds, rate,
                static_cast<int>(status.size()), status.data());
  const std::lock_guard lock(liveMutex());
  const bool erase = !liveLine().empty();
  std::fputs(((erase ? "\r\033[K" : "") + std::string(text) + "\n").c_str(), stderr);
  liveLine().clear();
}

void printAboveProgress(std::string_view line) {
  const std::lock_guard lock(liveMutex());
  std::string text(line);
  text += "\n";
  if (liveLine().empty()) {
    std::fputs(text.c_str(), stderr);
    return;
  }
  std::fputs(("\r\033[K" + text + liveLine() + "\033[K").c_str(), stderr);
  std::fflush(stderr);
}

}  // namespace vrflow::run
