#include "vrflow/run/events.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>

#include "vrflow/run/runner.hpp"

namespace vrflow::run {
namespace {

// Writes all of `text` on `fd`; gives up quietly when the reader is gone (the run goes on).
void writeAll(int fd, const std::string& text) {
  const char* p = text.data();
  std::size_t left = text.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    p += n;
    left -= static_cast<std::size_t>(n);
  }
}

}  // namespace

EventStream::EventStream(Writer writer, bool withStats)
    : writer_(std::move(writer)), withStats_(withStats) {}

Result<std::unique_ptr<EventStream>> EventStream::open(const std::string& target) {
  const int fd = target == "-"
                     ? fcntl(STDOUT_FILENO, F_DUPFD_CLOEXEC, 3)
                     : ::open(target.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    return makeError("cannot write the events to '" + target + "': " + std::strerror(errno));
  }
  auto stream =
      std::make_unique<EventStream>([fd](const std::string& line) { writeAll(fd, line + "\n"); });
  stream->fd_ = fd;
  return stream;
}

EventStream::~EventStream() {
  if (fd_ >= 0) close(fd_);
}

double EventStream::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void EventStream::tee(Writer tee) {
  std::lock_guard lock(mutex_);
  tee_ = std::move(tee);
}

void EventStream::write(const std::string& line) {
  std::lock_guard lock(mutex_);
  if (writer_) writer_(line);
  if (tee_) tee_(line);
}

void EventStream::started(const app::Application& application) {
  nlohmann::ordered_json j{{"event", "started"},
                           {"time", elapsed()},
                           {"application", application.name},
                           {"file", application.file}};
  auto hosts = nlohmann::ordered_json::array();
  for (const auto& h : application.hosts) hosts.push_back({{"id", h.id}, {"address", h.address}});
  j["hosts"] = hosts;
  auto modules = nlohmann::ordered_json::array();
  for (const auto& m : application.modules) {
    modules.push_back({{"id", m.id},
                       {"type", m.package + "/" + m.type},
                       {"host", app::effectiveHost(application, m.host)}});
  }
  j["modules"] = modules;
  write(j.dump());
}

void EventStream::stats(const std::string& snapshotJson, const std::string& host) {
  if (!withStats_) return;
  auto snapshot = nlohmann::ordered_json::parse(snapshotJson, nullptr, /*allow_exceptions=*/false);
  if (!snapshot.is_object()) return;
  nlohmann::ordered_json j{{"event", "stats"}, {"time", elapsed()}};
  if (!host.empty()) j["host"] = host;
  for (auto& [key, value] : snapshot.items()) j[key] = std::move(value);
  write(j.dump());
}

void EventStream::warning(const std::string& text, const std::string& host) {
  nlohmann::ordered_json j{{"event", "warning"}, {"time", elapsed()}};
  if (!host.empty()) j["host"] = host;
  j["text"] = text;
  write(j.dump());
}

void EventStream::moduleExit(const std::string& module, const std::string& host,
                             const std::string& exit, const std::string& cause) {
  nlohmann::ordered_json j{{"event", "module_exit"},
                           {"time", elapsed()},
                           {"module", module},
                           {"host", host},
                           {"exit", exit}};
  if (!cause.empty()) j["cause"] = cause;
  write(j.dump());
}

void EventStream::end(const RunOutcome& outcome) {
  write(nlohmann::ordered_json{{"event", "end"},
                               {"time", elapsed()},
                               {"exit_code", outcome.exitCode},
                               {"status", outcome.status},
                               {"error", outcome.error}}
            .dump());
}

void EventStream::relay(const std::string& line, const std::string& host) {
  auto j = nlohmann::ordered_json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object() || !j.contains("event")) return;
  if (j["event"] == "started" || j["event"] == "end") return;
  j["time"] = elapsed();  // on this stream's clock
  if (!j.contains("host")) j["host"] = host;
  write(j.dump());
}

}  // namespace vrflow::run
