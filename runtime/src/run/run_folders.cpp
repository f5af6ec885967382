// Run ids and the per-user folders of runs (run_folders.hpp).
#include "vrflow/run/run_folders.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>

namespace vrflow::run {

std::string newRunId(std::string_view application) {
  std::string id;
  for (const char c : application) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                       c == '_' || c == '.' || c == '-';
    id += plain ? c : '_';
  }
  if (id.empty()) id = "run";
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &local);
  return id + "-" + stamp + "-" + std::to_string(getpid());
}

Result<std::string> runtimeDirectory() {
  std::string dir;
  if (const char* runtime = std::getenv("XDG_RUNTIME_DIR");
      runtime != nullptr && *runtime != '\0') {
    dir = std::string(runtime) + "/vrflow";
  } else {
    dir = "/tmp/vrflow-" + std::to_string(getuid());
  }
  if (mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
    return makeError("cannot create the runtime folder '" + dir + "': " + std::strerror(errno));
  }
  // As ssh and tmux do: a folder that someone else owns or may write to could hand our files
  // (or links in their place) to another user.
  struct stat info {};
  if (lstat(dir.c_str(), &info) != 0) {
    return makeError("cannot use the runtime folder '" + dir + "': " + std::strerror(errno));
  }
  if (!S_ISDIR(info.st_mode)) {
    return makeError("the runtime folder '" + dir + "' is not a folder (a link or a file): " +
                     "remove it, or set XDG_RUNTIME_DIR");
  }
  if (info.st_uid != getuid()) {
    return makeError("the runtime folder '" + dir + "' belongs to uid " +
                     std::to_string(info.st_uid) + ", not to you (uid " + std::to_string(getuid()) +
                     "): remove it, or set XDG_RUNTIME_DIR");
  }
  if ((info.st_mode & (S_IWGRP | S_IWOTH)) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(info.st_mode & 07777));
    return makeError("the runtime folder '" + dir + "' may be written by others (mode " + mode +
                     "): make it private with `chmod 700 " + dir + "`");
  }
  return dir;
}

std::string stateDirectory() {
  if (const char* state = std::getenv("XDG_STATE_HOME"); state != nullptr && *state == '/') {
    return std::string(state) + "/vrflow";
  }
  if (const char* home = std::getenv("HOME"); home != nullptr && *home == '/') {
    return std::string(home) + "/.local/state/vrflow";
  }
  return "/tmp/vrflow-state-" + std::to_string(getuid());
}

std::string defaultLogDirectory(const std::string& runId) {
  return stateDirectory() + "/logs/" + runId;
}

}  // namespace vrflow::run
