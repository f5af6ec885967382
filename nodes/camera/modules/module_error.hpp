#pragma once
// How the camera modules report an error that stops them: one line naming the program and the
// module, then exit status 1 (the run reports it and stops).
#include <cstdio>
#include <string>

#include "vrflow/module/module.hpp"

namespace vrflow::camera {

/// Prints "PROGRAM: module 'ID': WHY" on stderr; returns the exit status to leave main() with.
inline int moduleError(const Module& module, const char* program, const std::string& why) {
  std::fprintf(stderr, "%s: module '%s': %s\n", program, module.id().c_str(), why.c_str());
  return 1;
}

}  // namespace vrflow::camera
