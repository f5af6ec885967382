#include "module_output.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

namespace vrflow::run::detail {
namespace {

long long nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// A line of `mpirun --tag-output`: "[JOB,RANK]<stdout>:TEXT" (or <stderr>, <stddiag>). Sets
// `rank` and `text` when the line has that form.
bool untag(std::string_view line, int& rank, std::string_view& text) {
  if (line.empty() || line.front() != '[') return false;
  const std::size_t comma = line.find(',');
  const std::size_t close = line.find("]<");
  if (comma == std::string_view::npos || close == std::string_view::npos || comma > close) {
    return false;
  }
  const std::size_t colon = line.find(">:", close);
  if (colon == std::string_view::npos) return false;
  int value = 0;
  for (std::size_t i = comma + 1; i < close; ++i) {
    if (line[i] < '0' || line[i] > '9' || value > 1'000'000) return false;
    value = value * 10 + (line[i] - '0');
  }
  rank = value;
  text = line.substr(colon + 2);
  return true;
}

}  // namespace

ModuleOutput::~ModuleOutput() {
  finish(0);
}

Result<int> ModuleOutput::add(std::vector<std::size_t> modules, bool mpiTagged) {
  int ends[2];
  if (pipe2(ends, O_CLOEXEC) != 0) {
    return makeError(std::string("cannot make a pipe for a module's output: ") +
                     std::strerror(errno));
  }
  fcntl(ends[0], F_SETFL, fcntl(ends[0], F_GETFL) | O_NONBLOCK);
  auto source = std::make_unique<Source>();
  source->fd = ends[0];
  source->modules = std::move(modules);
  source->mpiTagged = mpiTagged;
  std::lock_guard lock(mutex_);
  sources_.push_back(std::move(source));
  if (!thread_.joinable()) thread_ = std::thread([this] { readLoop(); });
  return ends[1];
}

void ModuleOutput::finish(double seconds) {
  deadlineNs_ = nowNs() + static_cast<long long>(seconds * 1e9);
  stopping_ = true;
  if (thread_.joinable()) thread_.join();
  logs_.flush();
}

void ModuleOutput::readLoop() {
  std::vector<Source*> open;
  std::vector<pollfd> fds;
  for (;;) {
    {
      std::lock_guard lock(mutex_);
      open.clear();
      for (auto& s : sources_) {
        if (s->fd >= 0) open.push_back(s.get());
      }
    }
    const bool pastDeadline = stopping_ && nowNs() >= deadlineNs_;
    if (stopping_ && (open.empty() || pastDeadline)) {
      // What is still there is read; a pipe that some escaped process keeps open is left.
      for (Source* s : open) {
        drain(*s);
        if (s->fd >= 0) {
          split(*s, /*atEnd=*/true);
          close(s->fd);
          s->fd = -1;
        }
      }
      logs_.flush();
      return;
    }
    fds.clear();
    for (Source* s : open) fds.push_back({s->fd, POLLIN, 0});
    // A short timeout: sources added meanwhile and the stop are seen within it.
    if (poll(fds.data(), fds.size(), 50) <= 0) continue;
    for (std::size_t i = 0; i < open.size(); ++i) {
      if (fds[i].revents != 0) drain(*open[i]);
    }
    logs_.flush();
  }
}

bool ModuleOutput::drain(Source& source) {
  char chunk[65536];
  // A bounded number of reads per turn: one module that floods must not starve the others.
  for (int turn = 0; turn < 16; ++turn) {
    const ssize_t n = read(source.fd, chunk, sizeof chunk);
    if (n > 0) {
      source.partial.append(chunk, static_cast<std::size_t>(n));
      split(source, false);
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return true;
    split(source, /*atEnd=*/true);  // the end: a last line without its newline is a line too
    close(source.fd);
    source.fd = -1;
    return false;
  }
  return true;
}

void ModuleOutput::split(Source& source, bool atEnd) {
  std::string_view rest = source.partial;
  std::size_t used = 0;
  for (;;) {
    const std::size_t eol = rest.find('\n');
    if (eol == std::string_view::npos) break;
    deliver(source, rest.substr(0, eol));
    rest.remove_prefix(eol + 1);
    used += eol + 1;
  }
  while (rest.size() >= kMaxLineBytes) {  // a line that long is cut into lines of that length
    deliver(source, rest.substr(0, kMaxLineBytes));
    rest.remove_prefix(kMaxLineBytes);
    used += kMaxLineBytes;
  }
  if (atEnd && !rest.empty()) {
    deliver(source, rest);
    used = source.partial.size();
  }
  source.partial.erase(0, used);
}

void ModuleOutput::deliver(const Source& source, std::string_view text) {
  int rank = -1;
  std::string_view untagged;
  if (source.mpiTagged && untag(text, rank, untagged)) {
    const auto r = static_cast<std::size_t>(rank);
    if (source.modules.size() > 1) {
      logs_.line(r < source.modules.size() ? source.modules[r] : source.modules.front(), untagged);
    } else {
      logs_.line(source.modules.front(), untagged, rank);
    }
    return;
  }
  logs_.line(source.modules.front(), text);
}

}  // namespace vrflow::run::detail
