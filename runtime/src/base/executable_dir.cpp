#include "vrflow/base/executable_dir.hpp"

#include <system_error>

namespace vrflow {

std::filesystem::path executableDir() {
  std::error_code error;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::path() : self.parent_path();
}

}  // namespace vrflow
