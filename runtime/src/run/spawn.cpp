#include "spawn.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "vrflow/run/process.hpp"

extern char** environ;

namespace vrflow::run {

Result<pid_t> spawnModule(const std::string& executable, const std::vector<std::string>& args,
                          int inheritFd, const std::vector<std::string>& extraEnvironment,
                          uint64_t memoryLimitBytes, int outputFd) {
  // An entry given here replaces the inherited one of the same name (a lookup takes the first).
  const auto overridden = [&](std::string_view entry) {
    const std::string_view name = entry.substr(0, entry.find('=') + 1);
    return std::any_of(extraEnvironment.begin(), extraEnvironment.end(),
                       [&](const std::string& e) { return e.starts_with(name); });
  };
  std::vector<std::string> envStrings;
  for (char** e = environ; *e != nullptr; ++e) {
    if (ipc::JoinContract::isContractEntry(*e)) {
      continue;  // ours are set below; inherited ones would shadow them or join a wrong run
    }
    if (overridden(*e)) continue;
    envStrings.emplace_back(*e);
  }
  for (const auto& e : extraEnvironment) envStrings.push_back(e);
  ProcessSettings settings;
  settings.argv = {executable};
  settings.argv.insert(settings.argv.end(), args.begin(), args.end());
  settings.environment = std::move(envStrings);
  settings.inheritFd = inheritFd;
  settings.stdoutFd = outputFd;
  settings.stderrFd = outputFd;
  settings.memoryLimitBytes = memoryLimitBytes;
  return spawnProcess(settings);
}

namespace {

// Starts `executable` as `ranks` ranks of one job through mpirun (VRFLOW_MPIRUN names another
// launcher), with `contract` exported to every rank (the segment by its /proc path instead of
// its descriptor: mpirun closes inherited descriptors). `what` names the job in the error.
Result<pid_t> spawnMpirun(const std::string& executable, int ranks, ipc::JoinContract contract,
                          const std::string& backingDir, uint64_t memoryLimitBytes, int outputFd,
                          const std::string& what) {
  const char* launcher = std::getenv("VRFLOW_MPIRUN");
  const std::string mpirun = launcher != nullptr && *launcher != '\0' ? launcher : "mpirun";
  contract.segmentPath =
      "/proc/" + std::to_string(getpid()) + "/fd/" + std::to_string(contract.segmentFd);
  contract.segmentFd = -1;
  std::vector<std::string> environment = contract.encode();
  // More ranks than cores is allowed; ranks that wait yield the core. Root (containers, CI)
  // must be allowed explicitly.
  // CMA single copies need ptrace rights that containers often withhold: copy through the
  // shared-memory transport's buffers instead.
  std::vector<std::string> args{"-np",
                                std::to_string(ranks),
                                "--oversubscribe",
                                "--mca",
                                "mpi_yield_when_idle",
                                "1",
                                "--mca",
                                "btl_vader_single_copy_mechanism",
                                "none"};
  if (!backingDir.empty()) {
    // The ranks' shared-memory files go to a folder the runtime removes, even after kill -9.
    args.insert(args.end(), {"--mca", "btl_vader_backing_directory", backingDir});
  }
  // Captured output: each line names the rank that wrote it (ModuleOutput routes it).
  if (outputFd >= 0) args.push_back("--tag-output");
  if (geteuid() == 0) {
    environment.push_back("OMPI_ALLOW_RUN_AS_ROOT=1");
    environment.push_back("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1");
  }
  for (const auto& e : environment) {
    if (ipc::JoinContract::isContractEntry(e)) {
      args.push_back("-x");
      args.push_back(e.substr(0, e.find('=')));
    }
  }
  args.push_back(executable);
  // The limit is inherited by the ranks, which mpirun forks.
  auto pid = spawnModule(mpirun, args, -1, environment, memoryLimitBytes, outputFd);
  if (!pid) {
    return makeError(pid.error().message + " (" + what +
                     " is started through mpirun: install Open MPI, or set VRFLOW_MPIRUN)");
  }
  return pid;
}

}  // namespace

Result<pid_t> spawnMpiModule(const std::string& executable, int ranks,
                             const ipc::JoinContract& contract, const std::string& backingDir,
                             uint64_t memoryLimitBytes, int outputFd) {
  ipc::JoinContract ranksContract = contract;
  ranksContract.mpiRanks = ranks;
  return spawnMpirun(executable, ranks, ranksContract, backingDir, memoryLimitBytes, outputFd,
                     "a module of " + std::to_string(ranks) + " MPI ranks");
}

Result<pid_t> spawnMpiJob(const std::string& executable, const std::vector<int>& slotIndices,
                          const ipc::JoinContract& contract, const std::string& backingDir,
                          uint64_t memoryLimitBytes, int outputFd) {
  ipc::JoinContract jobContract = contract;
  // One process per module: the modules' own index and id would name rank 0's to every rank.
  jobContract.moduleIndex = -1;
  jobContract.moduleId.clear();
  jobContract.moduleIndices = slotIndices;
  const int ranks = static_cast<int>(slotIndices.size());
  return spawnMpirun(executable, ranks, jobContract, backingDir, memoryLimitBytes, outputFd,
                     "an MPI job of " + std::to_string(ranks) + " modules");
}

namespace {

constexpr const char* kBackingParent = "/dev/shm";
constexpr const char* kBackingPrefix = "ompi-job.";

}  // namespace

MpiBackingFolder::~MpiBackingFolder() {
  if (path_.empty()) return;
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

Result<std::string> MpiBackingFolder::path() {
  if (!path_.empty()) return path_;
  std::string pattern =
      std::string(kBackingParent) + "/" + kBackingPrefix + std::to_string(getpid()) + ".XXXXXX";
  if (mkdtemp(pattern.data()) == nullptr) {  // mode 0700
    return makeError("cannot make a folder for the MPI jobs' shared memory in " +
                     std::string(kBackingParent) + ": " + std::strerror(errno));
  }
  path_ = pattern;
  return path_;
}

void removeStaleMpiBackingFolders() {
  DIR* dir = opendir(kBackingParent);
  if (dir == nullptr) return;
  const std::size_t prefix = std::strlen(kBackingPrefix);
  while (dirent* entry = readdir(dir)) {
    const std::string name = entry->d_name;
    if (name.compare(0, prefix, kBackingPrefix) != 0) continue;
    char* end = nullptr;
    const long pid = std::strtol(name.c_str() + prefix, &end, 10);
    if (pid <= 0 || *end != '.') continue;
    struct stat info {};
    if (fstatat(dirfd(dir), entry->d_name, &info, AT_SYMLINK_NOFOLLOW) != 0 ||
        !S_ISDIR(info.st_mode) || info.st_uid != getuid()) {
      continue;
    }
    if (kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // its runtime lives
    std::error_code ignored;
    std::filesystem::remove_all(std::string(kBackingParent) + "/" + name, ignored);
  }
  closedir(dir);
}

namespace {

std::string signalText(int sig) {
  const char* name = strsignal(sig);
  return "signal " + std::to_string(sig) + " (" + (name ? name : "?") + ")";
}

}  // namespace

std::string describeWaitStatus(int status) {
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return "was killed by " + signalText(WTERMSIG(status));
  return "ended with wait status " + std::to_string(status);
}

std::string describeMpirunWaitStatus(int status) {
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 0;
  if (code > 128 && code - 128 < NSIG) {  // Open MPI's odls: exit code = WTERMSIG + 128
    return describeWaitStatus(status) + " (an MPI rank was killed by " + signalText(code - 128) +
           ")";
  }
  return describeWaitStatus(status);
}

}  // namespace vrflow::run
