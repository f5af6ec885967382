#include "file_io.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "vrflow/base/file_access.hpp"

namespace vrflow::app::detail {

Result<std::string> readWholeFile(const std::string& path) {
  return readRegularFile(path, kMaxDescriptionFileBytes);
}

Status writeWholeFile(const std::string& path, const std::string& content) try {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) {
      return makeError(path + ": error: cannot write file (" + std::strerror(errno) + ")");
    }
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.flush();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      return makeError(path + ": error: cannot write file (write failed)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    return makeError(path + ": error: cannot write file (" + ec.message() + ")");
  }
  return {};
} catch (const std::exception& e) {
  return makeError(path + ": error: cannot write file (" + e.what() + ")");
}

}  // namespace vrflow::app::detail
