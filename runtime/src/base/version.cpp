// vrflow's version (vrflow/base/version.hpp), and the answer to `--version` that every program
// linking libvrflow_module gives before its main() runs.
#include "vrflow/base/version.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "vrflow_version_git.hpp"  // VRFLOW_GIT_DESCRIBE, written at build time

namespace vrflow {

std::string_view versionText() {
  static const std::string text = [] {
    std::string t(kVersion);
    if (std::strlen(VRFLOW_GIT_DESCRIBE) > 0) t += " (git " VRFLOW_GIT_DESCRIBE ")";
    return t;
  }();
  return text;
}

std::string versionLine(std::string_view program) {
  if (const auto slash = program.rfind('/'); slash != std::string_view::npos) {
    program.remove_prefix(slash + 1);
  }
  return std::string(program) + ": vrflow " + std::string(versionText());
}

namespace {

// glibc calls a shared library's initialisers with the program's (argc, argv, envp) (as
// _dl_init does for every object, DT_INIT_ARRAY included): a program started as exactly
// `PROGRAM --version` prints its version line and exits 0 before its main(). This gives every
// module (whose main() takes no argv), node executable and program the same answer without
// code of their own. Only argc == 2 with argv[1] == "--version" answers: the runtime starts
// modules with no arguments, so a run never reaches this.
#if defined(__GLIBC__)
__attribute__((constructor)) void answerVersion(int argc, char** argv, char** /*envp*/) {
  if (argc != 2 || argv == nullptr || argv[0] == nullptr || argv[1] == nullptr) return;
  if (std::strcmp(argv[1], "--version") != 0) return;
  const std::string line = versionLine(argv[0]) + "\n";
  std::fputs(line.c_str(), stdout);
  std::exit(std::fflush(stdout) == 0 ? 0 : 1);
}
#endif

}  // namespace
}  // namespace vrflow
