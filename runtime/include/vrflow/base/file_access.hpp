#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "vrflow/base/result.hpp"

namespace vrflow {

/// The most bytes read from an application, package manifest or composite file: 16 MiB.
inline constexpr std::size_t kMaxDescriptionFileBytes = std::size_t{16} << 20;
/// The most bytes a module reads from a data file named by a parameter (a rigid scene, a
/// mass-spring net, a camera path): 256 MiB.
inline constexpr std::size_t kMaxDataFileBytes = std::size_t{256} << 20;

/// Opens `path` for reading only if it is a regular file of at most `maxBytes` bytes: the
/// descriptor (close-on-exec, blocking), or an error "cannot read file (REASON)" without the
/// path. The file is opened with O_NONBLOCK before it is checked, so a FIFO never blocks, and a
/// directory, FIFO, device or socket is refused with what it is.
Result<int> openRegularFile(const std::string& path, std::size_t maxBytes);

/// The whole content of the regular file `path` of at most `maxBytes` bytes (checked before
/// and while reading, so a file that grows cannot exceed it), or an error "cannot read file
/// (REASON)" without the path (the caller names the file).
Result<std::string> readRegularFile(const std::string& path, std::size_t maxBytes);

/// Whether `path` is a regular file (symbolic links followed), without opening it: an error
/// "it is a FIFO, not a regular file", "No such file or directory", ... when not.
Status checkRegularFile(const std::string& path);

/// True when `path` is relative and stays inside the working folder (it does not climb out with
/// ".."): where a run may create the folders of its outputs.
bool insideWorkingFolder(std::string_view path);

/// Whether the output `path` (a file, or a folder for a folder-valued parameter) may be written:
/// its folder exists, or is missing inside the working folder where it may be created; an
/// error naming the folder otherwise. Creates nothing.
Status checkOutputPath(const std::string& path);

/// Makes sure the folder that will hold the output `path` exists: missing folders are created
/// only inside the working folder; elsewhere the folder must exist already (an error naming it
/// otherwise). The rule of every output file parameter (docs/application-format.md).
Status prepareOutputPath(const std::string& path);

}  // namespace vrflow
