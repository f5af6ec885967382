#include "vrflow/run/log.hpp"

#include <spdlog/logger.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/sinks/basic_file_sink.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>

#include "vrflow/run/module_logs.hpp"
#include "vrflow/run/progress.hpp"

namespace vrflow::run {
namespace {

constexpr std::array<std::string_view, 6> kLevelWords = {"trace", "debug", "info",
                                                         "warn",  "error", "off"};

spdlog::level::level_enum spdlogLevel(LogLevel level) {
  switch (level) {
    case LogLevel::Trace:
      return spdlog::level::trace;
    case LogLevel::Debug:
      return spdlog::level::debug;
    case LogLevel::Info:
      return spdlog::level::info;
    case LogLevel::Warn:
      return spdlog::level::warn;
    case LogLevel::Error:
      return spdlog::level::err;
    case LogLevel::Off:
      break;
  }
  return spdlog::level::off;
}

// The terminal's sink: each line goes above the live progress line (printAboveProgress), its
// level coloured on a terminal.
class TerminalSink final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  explicit TerminalSink(bool colour) : colour_(colour) {}

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    spdlog::memory_buf_t formatted;
    formatter_->format(msg, formatted);
    std::string line(formatted.data(), formatted.size());
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    if (colour_ && msg.color_range_end > msg.color_range_start &&
        msg.color_range_end <= line.size()) {
      line.insert(msg.color_range_end, "\033[0m");
      line.insert(msg.color_range_start, colourOf(msg.level));
    }
    printAboveProgress(line);
  }
  void flush_() override { std::fflush(stderr); }

 private:
  static const char* colourOf(spdlog::level::level_enum level) {
    switch (level) {
      case spdlog::level::trace:
      case spdlog::level::debug:
        return "\033[36m";  // cyan
      case spdlog::level::info:
        return "\033[32m";  // green
      case spdlog::level::warn:
        return "\033[33;1m";  // bold yellow
      default:
        return "\033[31;1m";  // bold red
    }
  }

  bool colour_;
};

std::shared_ptr<spdlog::logger> makeLogger(LogLevel level,
                                           std::shared_ptr<spdlog::sinks::sink> file) {
  auto terminal = std::make_shared<TerminalSink>(ModuleLogs::colourOnTerminal());
  terminal->set_pattern("%H:%M:%S.%e %^%l%$ %v");
  std::vector<spdlog::sink_ptr> sinks{terminal};
  if (file) sinks.push_back(std::move(file));
  auto logger = std::make_shared<spdlog::logger>("vrflow", sinks.begin(), sinks.end());
  logger->set_level(spdlogLevel(level));
  logger->flush_on(spdlog::level::trace);  // every line reaches the file, even before a crash
  return logger;
}

// The logger of this process, replaced by setupLogging(); copied under the lock by each line.
struct Current {
  std::mutex mutex;
  std::shared_ptr<spdlog::logger> logger = makeLogger(LogLevel::Info, nullptr);
};

// Never destroyed: a thread may still log while the process exits.
Current& current() {
  static Current* const instance = new Current;  // NOLINT(cppcoreguidelines-owning-memory)
  return *instance;
}

std::shared_ptr<spdlog::logger> logger() {
  Current& c = current();
  std::lock_guard lock(c.mutex);
  return c.logger;
}

}  // namespace

Result<LogLevel> parseLogLevel(std::string_view word) {
  for (std::size_t i = 0; i < kLevelWords.size(); ++i) {
    if (kLevelWords[i] == word) return static_cast<LogLevel>(i);
  }
  return makeError("unknown log level '" + std::string(word) +
                   "' (expected trace, debug, info, warn, error or off)");
}

Status setupLogging(LogLevel level, const std::string& logDir) {
  std::shared_ptr<spdlog::sinks::sink> file;
  if (!logDir.empty()) {
    const std::string path = logDir + "/vrflow.log";
    try {
      file = std::make_shared<spdlog::sinks::basic_file_sink_mt>(path);
    } catch (const spdlog::spdlog_ex& e) {
      return makeError("cannot write the log '" + path + "': " + e.what());
    }
    file->set_pattern("%Y-%m-%d %H:%M:%S.%e %l [%P] %v");
  }
  auto made = makeLogger(level, std::move(file));
  Current& c = current();
  std::lock_guard lock(c.mutex);
  c.logger = std::move(made);
  return {};
}

void shutdownLogging() {
  auto made = makeLogger(LogLevel::Info, nullptr);
  Current& c = current();
  std::lock_guard lock(c.mutex);
  made->set_level(c.logger->level());
  c.logger = std::move(made);
}

Status prepareLogDirectory(const std::string& dir) {
  const std::string what = "cannot use the log folder '" + dir + "': ";
  struct stat info {};
  if (stat(dir.c_str(), &info) != 0) {
    if (errno != ENOENT) return makeError(what + std::strerror(errno));
    std::error_code ec;
    const std::filesystem::path path(dir);
    if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path(), ec);
    if (mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
      return makeError(what + std::strerror(errno));
    }
    if (stat(dir.c_str(), &info) != 0) return makeError(what + std::strerror(errno));
  }
  if (!S_ISDIR(info.st_mode)) return makeError(what + "it is not a folder");
  if (access(dir.c_str(), W_OK | X_OK) != 0) return makeError(what + "it is not writable");
  return {};
}

void logTrace(const std::string& text) {
  logger()->trace(text);
}

void logDebug(const std::string& text) {
  logger()->debug(text);
}

void logInfo(const std::string& text) {
  logger()->info(text);
}

void logWarning(const std::string& text) {
  logger()->warn(text);
}

void logError(const std::string& text) {
  logger()->error(text);
}

}  // namespace vrflow::run
