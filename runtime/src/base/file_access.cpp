#include "vrflow/base/file_access.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "vrflow/base/echo.hpp"

namespace vrflow {
namespace {

Error readError(const std::string& reason) {
  return makeError("cannot read file (" + reason + ")");
}

// What a file that is not a regular one is, for the message.
const char* kindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "a special file";
}

Error tooLarge(const std::string& size, std::size_t maxBytes) {
  const std::string mib =
      maxBytes >= (1u << 20) ? " (" + std::to_string(maxBytes >> 20) + " MiB)" : std::string();
  return readError(size + ", above the limit of " + std::to_string(maxBytes) + " bytes" + mib);
}

}  // namespace

Result<int> openRegularFile(const std::string& path, std::size_t maxBytes) {
  // O_NONBLOCK: opening a FIFO without a writer returns at once instead of waiting for one.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) return readError(std::strerror(errno));
  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    const int error = errno;
    ::close(fd);
    return readError(std::strerror(error));
  }
  if (!S_ISREG(info.st_mode)) {
    ::close(fd);
    return readError(std::string("it is ") + kindOf(info.st_mode) + ", not a regular file");
  }
  if (static_cast<unsigned long long>(info.st_size) > maxBytes) {
    ::close(fd);
    return tooLarge("it is " + std::to_string(info.st_size) + " bytes", maxBytes);
  }
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
    const int error = errno;
    ::close(fd);
    return readError(std::strerror(error));
  }
  return fd;
}

Result<std::string> readRegularFile(const std::string& path, std::size_t maxBytes) {
  Result<int> fd = openRegularFile(path, maxBytes);
  if (!fd) return fd.error();
  std::string content;
  char buffer[65536];
  for (;;) {
    const ssize_t got = ::read(*fd, buffer, sizeof buffer);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      const int error = errno;
      ::close(*fd);
      return readError(std::strerror(error));
    }
    if (got == 0) break;
    // A file that grows while it is read (a log, a /proc file whose size reads 0) is cut here.
    if (content.size() + static_cast<std::size_t>(got) > maxBytes) {
      ::close(*fd);
      return tooLarge("it grew while it was read", maxBytes);
    }
    content.append(buffer, static_cast<std::size_t>(got));
  }
  ::close(*fd);
  return content;
}

Status checkRegularFile(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) return makeError(std::strerror(errno));
  if (!S_ISREG(info.st_mode)) {
    return makeError(std::string("it is ") + kindOf(info.st_mode) + ", not a regular file");
  }
  return {};
}

bool insideWorkingFolder(std::string_view path) {
  const std::filesystem::path normal = std::filesystem::path(path).lexically_normal();
  return normal.is_relative() && !normal.empty() && *normal.begin() != "..";
}

namespace {

// The folder that holds the output `path` ("" for one in the working folder itself).
std::filesystem::path folderOf(const std::string& path) {
  std::filesystem::path normal = std::filesystem::path(path).lexically_normal();
  if (!normal.has_filename()) normal = normal.parent_path();  // "out/frames/"
  return normal.parent_path();
}

}  // namespace

Status checkOutputPath(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path folder = folderOf(path);
  std::error_code error;
  if (folder.empty() || fs::is_directory(folder, error)) return {};
  if (fs::exists(folder, error))
    return makeError(quotedValue(folder.string()) + " is not a folder");
  if (!insideWorkingFolder(path)) {
    return makeError("folder " + quotedValue(folder.string()) +
                     " does not exist (folders are created only inside the run's working "
                     "folder; create it first)");
  }
  return {};
}

Status prepareOutputPath(const std::string& path) {
  if (Status checked = checkOutputPath(path); !checked) return checked;
  const std::filesystem::path folder = folderOf(path);
  std::error_code error;
  if (folder.empty() || std::filesystem::is_directory(folder, error)) return {};
  std::filesystem::create_directories(folder, error);
  if (error) {
    return makeError("cannot create folder " + quotedValue(folder.string()) + ": " +
                     error.message());
  }
  return {};
}

}  // namespace vrflow
