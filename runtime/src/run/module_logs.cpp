#include "vrflow/run/module_logs.hpp"

#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "vrflow/run/progress.hpp"

namespace vrflow::run {
namespace {

// One colour per module, in turn (ANSI: red, green, yellow, blue, magenta, cyan).
constexpr std::array<const char*, 6> kColours = {"\033[31m", "\033[32m", "\033[33m",
                                                 "\033[34m", "\033[35m", "\033[36m"};
constexpr const char* kReset = "\033[0m";

}  // namespace

ModuleLogs::ModuleLogs(Settings settings) : settings_(std::move(settings)) {}

ModuleLogs::~ModuleLogs() {
  flush();
  for (auto& m : modules_) {
    if (m.file != nullptr) std::fclose(m.file);
  }
}

bool ModuleLogs::colourOnTerminal() {
  const char* noColour = std::getenv("NO_COLOR");
  return isatty(STDERR_FILENO) != 0 && (noColour == nullptr || *noColour == '\0');
}

Result<std::size_t> ModuleLogs::add(const std::string& id, const std::string& host) {
  std::lock_guard lock(mutex_);
  for (std::size_t i = 0; i < modules_.size(); ++i) {
    if (modules_[i].id == id) return i;
  }
  Module m;
  m.id = id;
  m.host = host;
  m.prefix = "[" + id + "@" + host + "]";
  if (settings_.colour) {
    m.prefix = kColours[modules_.size() % kColours.size()] + m.prefix + kReset;
  }
  if (!settings_.logDir.empty()) {
    m.path = settings_.logDir + "/" + id + ".log";
    // "e": close-on-exec, so that no module inherits another's log.
    m.file = std::fopen(m.path.c_str(), "ae");
    if (m.file == nullptr) {
      return makeError("cannot write the log '" + m.path + "' of module '" + id +
                       "': " + std::strerror(errno));
    }
  }
  modules_.push_back(std::move(m));
  return modules_.size() - 1;
}

long ModuleLogs::find(const std::string& id) const {
  std::lock_guard lock(mutex_);
  for (std::size_t i = 0; i < modules_.size(); ++i) {
    if (modules_[i].id == id) return static_cast<long>(i);
  }
  return -1;
}

void ModuleLogs::append(Module& m, std::string_view text, const std::string& prefix) {
  if (settings_.echo) {
    pending_ += prefix;
    pending_ += ' ';
    pending_ += text;
    pending_ += '\n';
  }
  if (m.file != nullptr) {
    std::fwrite(text.data(), 1, text.size(), m.file);
    std::fputc('\n', m.file);
  }
  m.tail.emplace_back(text.substr(0, kTailLineBytes));
  if (m.tail.size() > kTailLines) m.tail.pop_front();
}

void ModuleLogs::line(std::size_t module, std::string_view text, int rank) {
  std::string id;
  {
    std::lock_guard lock(mutex_);
    Module& m = modules_.at(module);
    if (rank < 0) {
      append(m, text, m.prefix);
    } else {
      std::string prefix = m.prefix;
      prefix.insert(prefix.rfind(']'), " rank " + std::to_string(rank));
      append(m, text, prefix);
    }
    if (settings_.forward) id = m.id;
  }
  if (settings_.forward) settings_.forward(id, text);
}

void ModuleLogs::note(std::size_t module, std::string_view text) {
  std::lock_guard lock(mutex_);
  Module& m = modules_.at(module);
  append(m, "vrflow: " + std::string(text), m.prefix);
}

void ModuleLogs::flush() {
  std::lock_guard lock(mutex_);
  if (!pending_.empty()) {
    // Above the live progress line when one shows (it is redrawn below them).
    if (pending_.back() == '\n') pending_.pop_back();
    printAboveProgress(pending_);
    std::fflush(stderr);
    pending_.clear();
  }
  for (auto& m : modules_) {
    if (m.file != nullptr) std::fflush(m.file);
  }
}

std::string ModuleLogs::logFile(const std::string& id) const {
  std::lock_guard lock(mutex_);
  for (const auto& m : modules_) {
    if (m.id == id) return m.path;
  }
  return {};
}

std::vector<std::string> ModuleLogs::lastLines(const std::string& id) const {
  std::lock_guard lock(mutex_);
  for (const auto& m : modules_) {
    if (m.id == id) return {m.tail.begin(), m.tail.end()};
  }
  return {};
}

std::string droppedNote(uint64_t count) {
  return std::to_string(count) +
         " lines dropped (more than the control channel forwards; the host's own log, with "
         "--log-dir on its daemon, has them all)";
}

}  // namespace vrflow::run
