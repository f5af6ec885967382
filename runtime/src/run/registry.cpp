// The registry of runs (registry.hpp, docs/operations.md).
#include "vrflow/run/registry.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "vrflow/run/run_folders.hpp"

namespace vrflow::run {
namespace {

using nlohmann::json;

// A registry file larger than this is not ours (they hold a few KiB per host).
constexpr off_t kMaxRecordBytes = off_t{16} << 20;

// A regular file (never through a symbolic link) of at most kMaxRecordBytes; empty otherwise.
// Read to its end, not to its size: /proc's files say they are empty.
std::string readRecordFile(const std::string& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return {};
  struct stat info {};
  std::string text;
  if (fstat(fd, &info) == 0 && S_ISREG(info.st_mode)) {
    char buffer[16384];
    ssize_t n = 0;
    while ((n = read(fd, buffer, sizeof buffer)) > 0) {
      text.append(buffer, static_cast<std::size_t>(n));
      if (text.size() > static_cast<std::size_t>(kMaxRecordBytes)) {
        text.clear();
        break;
      }
    }
  }
  close(fd);
  return text;
}

// Replaces `folder`/`name` by `text`: written to a new temporary file (O_EXCL, never through a
// link), then renamed over it, so a reader sees the old file or the new one, whole.
bool writeRecordFile(const std::string& folder, const std::string& name, const std::string& text) {
  const std::string path = folder + "/" + name;
  std::string temp = path + ".XXXXXX";
  const int fd = mkostemp(temp.data(), O_CLOEXEC);
  if (fd < 0) return false;
  bool ok = fchmod(fd, 0600) == 0;
  for (std::size_t done = 0; ok && done < text.size();) {
    const ssize_t n = write(fd, text.data() + done, text.size() - done);
    ok = n > 0;
    if (ok) done += static_cast<std::size_t>(n);
  }
  ok = close(fd) == 0 && ok;
  if (ok && rename(temp.c_str(), path.c_str()) == 0) return true;
  unlink(temp.c_str());
  return false;
}

std::string identityJson(const RunIdentity& r) {
  return json{{"id", r.id},
              {"kind", r.kind},
              {"application", r.application},
              {"file", r.file},
              {"hosts", r.hosts},
              {"modules", r.modules},
              {"pid", r.pid},
              {"pid_start", r.pidStart},
              {"start_time", r.startTime},
              {"iterations", r.iterations},
              {"log_dir", r.logDir}}
      .dump();
}

std::optional<RunIdentity> identityFromJson(const std::string& text) {
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object() || !j.contains("id") || !j["id"].is_string()) return std::nullopt;
  RunIdentity r;
  r.id = j.value("id", "");
  r.kind = j.value("kind", "run");
  r.application = j.value("application", "");
  r.file = j.value("file", "");
  r.hosts = j.value("hosts", std::vector<std::string>{});
  r.modules = j.value("modules", std::vector<std::string>{});
  r.pid = j.value("pid", pid_t{0});
  r.pidStart = j.value("pid_start", uint64_t{0});
  r.startTime = j.value("start_time", int64_t{0});
  r.iterations = j.value("iterations", uint64_t{0});
  r.logDir = j.value("log_dir", "");
  return r;
}

// The start time of process `pid` (field 22 of /proc/PID/stat), or 0 if it does not run.
uint64_t processStart(pid_t pid) {
  if (pid <= 0) return 0;
  const std::string stat = readRecordFile("/proc/" + std::to_string(pid) + "/stat");
  const std::size_t paren = stat.rfind(')');  // the command name may hold spaces and ')'
  if (paren == std::string::npos) return 0;
  // After the name: field 3 (state) ... field 22 (starttime), 20 fields on.
  const char* p = stat.c_str() + paren + 1;
  for (int field = 3; field < 22; ++field) {
    while (*p == ' ') ++p;
    if (field == 3 && *p == 'Z') return 0;  // ended, not yet reaped
    while (*p != ' ' && *p != '\0') ++p;
  }
  return std::strtoull(p, nullptr, 10);
}

// A folder of ours for the registry's records: created 0700 if missing; never a link.
Result<std::string> privateFolder(const std::string& dir) {
  if (mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
    return makeError("cannot create the folder '" + dir + "': " + std::strerror(errno));
  }
  struct stat info {};
  if (lstat(dir.c_str(), &info) != 0 || !S_ISDIR(info.st_mode) || info.st_uid != getuid()) {
    return makeError("'" + dir +
                     "' is not a folder of yours (a link, a file, or another user's): "
                     "remove it");
  }
  return dir;
}

// The folder of ended runs: stateDirectory()/runs.
Result<std::string> endedDirectory() {
  std::error_code error;
  std::filesystem::create_directories(stateDirectory(), error);
  if (error) {
    return makeError("cannot create the state folder '" + stateDirectory() +
                     "': " + error.message());
  }
  return privateFolder(stateDirectory() + "/runs");
}

// The names of the folders in `dir` (no dot files).
std::vector<std::string> folderNames(const std::string& dir) {
  std::vector<std::string> names;
  DIR* d = opendir(dir.c_str());
  if (d == nullptr) return names;
  while (dirent* e = readdir(d)) {
    if (e->d_name[0] != '.') names.emplace_back(e->d_name);
  }
  closedir(d);
  return names;
}

std::optional<RunRecord> readRecord(const std::string& folder) {
  auto identity = identityFromJson(readRecordFile(folder + "/run.json"));
  if (!identity) return std::nullopt;
  RunRecord record;
  record.identity = std::move(*identity);
  record.state = RunState::fromJson(readRecordFile(folder + "/state.json"));
  record.folder = folder;
  return record;
}

// Removes the oldest ended runs beyond kMaxEndedRuns.
void pruneEnded(const std::string& ended) {
  std::vector<std::pair<int64_t, std::string>> runs;
  for (const auto& name : folderNames(ended)) {
    const auto identity = identityFromJson(readRecordFile(ended + "/" + name + "/run.json"));
    runs.emplace_back(identity ? identity->startTime : 0, name);
  }
  if (runs.size() <= kMaxEndedRuns) return;
  std::sort(runs.begin(), runs.end());
  std::error_code ignored;
  for (std::size_t i = 0; i + kMaxEndedRuns < runs.size(); ++i) {
    std::filesystem::remove_all(ended + "/" + runs[i].second, ignored);
  }
}

// Moves a run's folder from the registry to the ended runs; its new place, or empty.
std::string moveToEnded(const std::string& folder, const std::string& id) {
  auto ended = endedDirectory();
  if (!ended) return {};
  const std::string target = *ended + "/" + id;
  std::error_code ignored;
  if (rename(folder.c_str(), target.c_str()) != 0) {
    // Gone (ENOENT: its run, or another reader, moved it first), or already there: a target
    // is never removed, since it may be the run's own record, moved an instant ago.
    if (errno != EXDEV) return {};
    // Another file system: copied, then removed.
    if (mkdir(target.c_str(), 0700) != 0) return {};
    for (const char* name : {"run.json", "state.json"}) {
      writeRecordFile(target, name, readRecordFile(folder + "/" + name));
    }
    std::filesystem::remove_all(folder, ignored);
  }
  pruneEnded(*ended);
  return target;
}

}  // namespace

RunIdentity identityOf(const app::Application& application, const std::string& kind,
                       const std::string& runId, uint64_t iterations, const std::string& logDir) {
  RunIdentity r;
  r.id = runId;
  r.kind = kind;
  r.application = application.name;
  r.file = application.file;
  for (const auto& h : application.hosts) r.hosts.push_back(h.id);
  for (const auto& m : application.modules) r.modules.push_back(m.id);
  r.pid = getpid();
  r.pidStart = processStart(r.pid);
  r.startTime = static_cast<int64_t>(std::time(nullptr));
  r.iterations = iterations;
  r.logDir = logDir;
  return r;
}

bool processRuns(pid_t pid, uint64_t pidStart) {
  const uint64_t start = processStart(pid);
  return start != 0 && start == pidStart;
}

Result<std::string> registryDirectory() {
  auto runtime = runtimeDirectory();
  if (!runtime) return runtime.error();
  return privateFolder(*runtime + "/runs");
}

Result<std::unique_ptr<RunRegistration>> RunRegistration::create(const RunIdentity& identity) {
  auto dir = registryDirectory();
  if (!dir) return dir.error();
  const std::string folder = *dir + "/" + identity.id;
  if (mkdir(folder.c_str(), 0700) != 0) {
    return makeError("cannot register the run as '" + folder + "': " + std::strerror(errno));
  }
  std::unique_ptr<RunRegistration> registration(new RunRegistration(identity, folder));
  registration->save();
  if (!writeRecordFile(folder, "run.json", identityJson(identity))) {
    std::error_code ignored;
    std::filesystem::remove_all(folder, ignored);
    return makeError("cannot write the run's record in '" + folder + "'");
  }
  return registration;
}

RunRegistration::RunRegistration(RunIdentity identity, std::string folder)
    : identity_(std::move(identity)), folder_(std::move(folder)) {}

RunRegistration::~RunRegistration() {
  if (!state_.ended()) state_.endAs("ended", "");
  save();
  moveToEnded(folder_, identity_.id);
}

void RunRegistration::event(const std::string& line) {
  state_.take(line);
  save();
}

void RunRegistration::save() {
  writeRecordFile(folder_, "state.json", state_.toJson());
}

RegisteredRun::RegisteredRun(const RunIdentity& identity, EventStream* given) : events_(given) {
  auto registration = RunRegistration::create(identity);
  if (!registration) {
    std::fprintf(stderr,
                 "vrflow: warning: `vrflow list` and `vrflow monitor` will not show this %s: %s\n",
                 identity.kind.c_str(), registration.error().message.c_str());
    return;
  }
  registration_ = std::move(*registration);
  if (events_ == nullptr) {
    own_ = std::make_unique<EventStream>(EventStream::Writer());
    events_ = own_.get();
  }
  events_->tee(
      [registration = registration_.get()](const std::string& line) { registration->event(line); });
}

RegisteredRun::~RegisteredRun() {
  if (registration_ != nullptr) events_->tee({});
}

std::string RunRecord::stateWord() const {
  return running ? std::string("running") : state.endStatus();
}

Result<std::vector<RunRecord>> listRuns(bool all) {
  auto dir = registryDirectory();
  if (!dir) return dir.error();
  std::vector<RunRecord> runs;
  for (const auto& name : folderNames(*dir)) {
    auto record = readRecord(*dir + "/" + name);
    if (!record) continue;  // being created, or not a run's
    record->running = processRuns(record->identity.pid, record->identity.pidStart);
    if (record->running) {
      runs.push_back(std::move(*record));
      continue;
    }
    // Its process is gone and did not move it: killed (SIGKILL, a crash) before its end.
    const bool lost = !record->state.ended();
    if (lost) {
      record->state.endAs("lost", "the vrflow process (pid " +
                                      std::to_string(record->identity.pid) +
                                      ") ended without finishing the run (killed?)");
      writeRecordFile(record->folder, "state.json", record->state.toJson());
    }
    record->folder = moveToEnded(record->folder, record->identity.id);
    if (lost && !all && !record->folder.empty()) runs.push_back(std::move(*record));
  }
  if (all) {
    if (auto ended = endedDirectory()) {
      for (const auto& name : folderNames(*ended)) {
        if (auto record = readRecord(*ended + "/" + name)) runs.push_back(std::move(*record));
      }
    }
  }
  std::stable_sort(runs.begin(), runs.end(), [](const RunRecord& a, const RunRecord& b) {
    return a.identity.startTime != b.identity.startTime
               ? a.identity.startTime < b.identity.startTime
               : a.identity.id < b.identity.id;
  });
  return runs;
}

Result<RunRecord> findRun(const std::string& prefix, bool all) {
  auto runs = listRuns(all);
  if (!runs) return runs.error();
  const auto names = [](const std::vector<const RunRecord*>& list) {
    std::string text;
    for (const RunRecord* r : list) text += (text.empty() ? "" : ", ") + r->identity.id;
    return text;
  };
  std::vector<const RunRecord*> candidates;
  for (const auto& r : *runs) {
    if (prefix.empty() ? r.running : r.identity.id.rfind(prefix, 0) == 0) candidates.push_back(&r);
    if (!prefix.empty() && r.identity.id == prefix) return r;  // a whole id is never ambiguous
  }
  if (candidates.size() == 1) return *candidates.front();
  if (prefix.empty()) {
    if (candidates.empty()) {
      return makeError("no run is running (`vrflow list --all` shows the ended ones)");
    }
    return makeError(std::to_string(candidates.size()) + " runs are running: " + names(candidates) +
                     "; name one (any unique start of its id)");
  }
  if (!candidates.empty()) {
    return makeError("'" + prefix + "' is the start of several runs' ids: " + names(candidates) +
                     "; give more of it");
  }
  std::vector<const RunRecord*> known;
  for (const auto& r : *runs) known.push_back(&r);
  return makeError("no run '" + prefix + "'" +
                   (known.empty()
                        ? std::string(all ? "; no run is registered" : "; no run is running")
                        : "; the runs are: " + names(known)));
}

}  // namespace vrflow::run
