#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

#include "vrflow/base/result.hpp"

namespace vrflow::run {

/// Starts `executable` as a module process: its own process group (Ctrl-C reaches only the
/// runtime, which stops modules in order), killed if the runtime dies, with the segment's
/// descriptor inherited and the given extra environment.
Result<pid_t> spawnModule(const std::string& executable, const std::vector<std::string>& args,
                          int inheritFd, const std::vector<std::string>& extraEnvironment);

/// "exited with status 3" / "was killed by signal 11 (Segmentation fault)".
std::string describeWaitStatus(int status);

}  // namespace vrflow::run
