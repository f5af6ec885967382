// testing/chatter: prints on stdout and stderr for the log tests: `lines` numbered lines on each,
// its open descriptors above 2 (`fds`), `flood` MiB of output, a last line without its newline
// (`partial`), then runs until `crash` (SIGSEGV at that iteration; 0: never) or its end.
#include <dirent.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "vrflow/module/module.hpp"

namespace {

// "fd N -> TARGET" for each descriptor above 2 (the one that lists them excluded).
void printDescriptors() {
  DIR* dir = opendir("/proc/self/fd");
  if (dir == nullptr) return;
  while (dirent* entry = readdir(dir)) {
    const int fd = std::atoi(entry->d_name);
    if (fd <= 2 || fd == dirfd(dir)) continue;
    char target[512] = {};
    const ssize_t n = readlink(("/proc/self/fd/" + std::string(entry->d_name)).c_str(), target,
                               sizeof target - 1);
    std::printf("fd %d -> %s\n", fd, n > 0 ? target : "?");
  }
  closedir(dir);
}

}  // namespace

int main() {
  vrflow::Module module;
  auto& out = module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const auto lines = module.params().getInt("lines");
  for (long i = 1; i <= lines; ++i) {
    std::printf("out %ld\n", i);  // not flushed: a module's stdout is line-buffered
    std::fprintf(stderr, "err %ld\n", i);
  }
  if (module.params().getInt("fds") != 0) printDescriptors();
  const long floodMiB = module.params().getInt("flood");
  if (floodMiB > 0) {
    std::string line(99, 'x');
    line += '\n';
    const long count = floodMiB * 1024 * 1024 / static_cast<long>(line.size());
    for (long i = 0; i < count; ++i) std::fwrite(line.data(), 1, line.size(), stdout);
    std::printf("flood done\n");
  }
  const std::string partial = module.params().getString("partial");
  if (!partial.empty()) {
    std::printf("%s", partial.c_str());
    std::fflush(stdout);
  }
  const auto crashAt = static_cast<uint64_t>(module.params().getInt("crash"));
  while (module.wait()) {
    if (crashAt > 0 && module.iteration() == crashAt) {
      std::fprintf(stderr, "about to crash\n");
      // Dies by the signal itself, also in a sanitizer build (whose handler would report and
      // exit instead).
      std::signal(SIGSEGV, SIG_DFL);
      std::raise(SIGSEGV);
    }
    if (!module.put(out, module.newMessage())) break;
  }
  return module.exitStatus();
}
