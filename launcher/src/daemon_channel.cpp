// What the daemons of a launch say on their control channels, and how the launcher acts on it.
#include <poll.h>
#include <signal.h>
#include <sys/signalfd.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>

#include "launcher.hpp"
#include "vrflow/run/events.hpp"
#include "vrflow/run/log.hpp"

namespace vrflow::launcher::detail {
namespace {

std::string describeStatus(int status) {
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    return "was killed by signal " + std::to_string(WTERMSIG(status)) + " (" +
           strsignal(WTERMSIG(status)) + ")";
  }
  return "ended";
}

}  // namespace

void Launcher::onLine(HostDaemon& d, const std::string& line) {
  auto parsed = net::parseControlEvent(line);
  if (!parsed) return;  // not a line of the protocol: nothing to act on
  net::ControlEvent& event = *parsed;
  using Kind = net::ControlEvent::Kind;
  switch (event.kind) {
    case Kind::Hello:
      break;  // only on mpirun's control socket, before the channel is the daemon's
    case Kind::Listening:
      d.port = event.port;
      break;
    case Kind::Connected:
      d.connected = true;
      break;
    case Kind::Stopping:
      d.stopAnswered = true;
      break;
    case Kind::Error:
      failWith({run::kExitRunFailed, "failed", "host '" + d.host + "': " + event.text}, true);
      break;
    case Kind::Finished:
      d.finished = true;
      d.finishedCode = event.exitCode;
      d.finishedStatus = event.status;
      d.finishedError = event.text;
      if (d.finishedCode != 0 && d.finishedStatus != "stopped") {
        const bool lostLink = d.finishedError.rfind("lost the link", 0) == 0;
        failWith({d.finishedCode, d.finishedStatus, "host '" + d.host + "': " + d.finishedError},
                 !lostLink);
      }
      break;
    case Kind::Report:
      d.report = std::move(event.text);
      break;
    case Kind::Stats:
      if (events_ != nullptr) events_->stats(event.text, d.host);
      d.stats = std::move(event.text);
      break;
    case Kind::Event:
      if (events_ != nullptr) events_->relay(event.text, d.host);
      break;
    case Kind::Trace:
      d.trace = std::move(event.text);
      break;
    case Kind::Output:
    case Kind::Dropped:
      onOutput(d, event);
      break;
    case Kind::Clock:
      // "clock T0 Td": our send time echoed with the daemon's clock; the daemon read its clock
      // about half-way through the round trip.
      d.clockOffsetNs = event.clockDaemonNs - (event.clockSentNs + steadyNs()) / 2;
      d.clockKnown = true;
      break;
  }
}

void Launcher::onOutput(const HostDaemon& d, const net::ControlEvent& event) {
  auto index = logs_.add(event.module, d.host);
  if (!index) {
    if (!logsRefused_) run::logWarning("vrflow: warning: " + index.error().message);
    logsRefused_ = true;
    return;
  }
  if (event.kind == net::ControlEvent::Kind::Dropped) {
    logs_.note(*index, run::droppedNote(event.dropped));
  } else {
    logs_.line(*index, event.text);
  }
}

void Launcher::pump(int timeoutMs) {
  std::vector<pollfd> fds;
  fds.push_back({signalFd_, POLLIN, 0});
  for (const auto& d : daemons_) fds.push_back({d.fromDaemon, POLLIN, 0});
  poll(fds.data(), fds.size(), timeoutMs);
  if (fds[0].revents & POLLIN) {
    signalfd_siginfo info{};
    while (read(signalFd_, &info, sizeof info) == sizeof info) {
      if ((info.ssi_signo == SIGINT || info.ssi_signo == SIGTERM) && !interrupted_) {
        interrupted_ = true;
        failWith(
            {run::kExitInterrupted, "interrupted",
             std::string("interrupted by ") + (info.ssi_signo == SIGINT ? "SIGINT" : "SIGTERM")},
            true);
      }
    }
  }
  for (std::size_t i = 0; i < daemons_.size(); ++i) {
    HostDaemon& d = daemons_[i];
    if (d.fromDaemon < 0) continue;
    char chunk[65536];
    while (true) {
      const ssize_t n = read(d.fromDaemon, chunk, sizeof chunk);
      if (n > 0) {
        d.buffer.append(chunk, static_cast<std::size_t>(n));
        continue;
      }
      if (n == 0) {
        close(d.fromDaemon);
        d.fromDaemon = -1;
        // Under mpirun every daemon has the same process (mpirun): the control channel's end
        // is what names the host that died.
        if (d.viaMpirun && !d.finished) {
          failWith(
              {run::kExitRunFailed, "failed", d.name() + " closed its control channel: it died"},
              true);
        }
      }
      break;
    }
    std::size_t eol = 0;
    while ((eol = d.buffer.find('\n')) != std::string::npos) {
      const std::string line = d.buffer.substr(0, eol);
      d.buffer.erase(0, eol + 1);
      onLine(d, line);
    }
  }
  int status = 0;
  pid_t pid = 0;
  while ((pid = waitpid(-1, &status, WNOHANG)) > 0) {
    for (auto& d : daemons_) {
      if (d.pid != pid || d.exited) continue;
      d.exited = true;
      d.exitText = describeStatus(status);
      // Read what it said last (its report, its finish line) before judging.
      if (d.fromDaemon >= 0) {
        char chunk[65536];
        ssize_t n = 0;
        while ((n = read(d.fromDaemon, chunk, sizeof chunk)) > 0) {
          d.buffer.append(chunk, static_cast<std::size_t>(n));
        }
        std::size_t eol = 0;
        while ((eol = d.buffer.find('\n')) != std::string::npos) {
          const std::string line = d.buffer.substr(0, eol);
          d.buffer.erase(0, eol + 1);
          onLine(d, line);
        }
      }
      if (!d.finished) {
        failWith({run::kExitRunFailed, "failed", d.name() + " " + d.exitText}, true);
      } else if (d.report.empty()) {
        // Without its share the merged report would silently lack this host's modules.
        failWith({run::kExitRunFailed, "failed",
                  d.name() + " " + d.exitText + " after its modules finished, without its report"},
                 true);
      }
      if (d.toDaemon >= 0) close(d.toDaemon);
      d.toDaemon = -1;
    }
  }
  logs_.flush();
}

}  // namespace vrflow::launcher::detail
