#pragma once

#include <filesystem>

namespace vrflow {

/// The folder of this process's executable (/proc/self/exe), empty if it cannot be read. vrflow's
/// programs find what ships with them from it: `../share/vrflow/packages`, `../lib/vrflow/filters`,
/// `vrflow-daemon` beside them, in the build tree and installs alike.
std::filesystem::path executableDir();

/// Makes executableDir() return `folder` from now on (empty: /proc/self/exe's folder again), for
/// a process that is no program of the tree but uses its libraries as one (the Python package
/// `vrflow` names its tree's `bin/`, as the interpreter's folder would mean nothing).
void setExecutableDir(std::filesystem::path folder);

}  // namespace vrflow
