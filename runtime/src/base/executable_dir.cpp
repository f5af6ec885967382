#include "vrflow/base/executable_dir.hpp"

#include <mutex>
#include <system_error>
#include <utility>

namespace vrflow {
namespace {

std::mutex& overrideMutex() {
  static std::mutex mutex;
  return mutex;
}

std::filesystem::path& overrideFolder() {
  static std::filesystem::path folder;
  return folder;
}

}  // namespace

std::filesystem::path executableDir() {
  {
    const std::lock_guard lock(overrideMutex());
    if (!overrideFolder().empty()) return overrideFolder();
  }
  std::error_code error;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::path() : self.parent_path();
}

void setExecutableDir(std::filesystem::path folder) {
  const std::lock_guard lock(overrideMutex());
  overrideFolder() = std::move(folder);
}

}  // namespace vrflow
