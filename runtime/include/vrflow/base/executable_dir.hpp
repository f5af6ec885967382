#pragma once

#include <filesystem>

namespace vrflow {

/// The folder of this process's executable (/proc/self/exe), empty if it cannot be read. vrflow's
/// programs find what ships with them from it: `../share/vrflow/packages`, `../lib/vrflow/filters`,
/// `vrflow-daemon` beside them, in the build tree and installs alike.
std::filesystem::path executableDir();

}  // namespace vrflow
