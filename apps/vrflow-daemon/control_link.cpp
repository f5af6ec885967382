#include "control_link.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>

#include "vrflow/daemon/daemon.hpp"
#include "vrflow/net/control.hpp"
#include "vrflow/run/log.hpp"

namespace vrflow::tools {
namespace {

using Kind = net::ControlCommand::Kind;

// One line from a descriptor, byte by byte (the secret must not be read ahead into a buffer
// shared with anything else); false at end of input.
bool readLine(int fd, std::string& line) {
  line.clear();
  char c = 0;
  while (true) {
    const ssize_t n = read(fd, &c, 1);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return !line.empty();
    if (c == '\n') return true;
    line += c;
    if (line.size() > 1 << 20) return true;
  }
}

int hostIndex(const app::Application& application, const std::string& host) {
  for (std::size_t i = 0; i < application.hosts.size(); ++i) {
    if (application.hosts[i].id == host) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace

Result<std::unique_ptr<ControlLink>> ControlLink::create(const app::Application& application,
                                                         const std::string& host,
                                                         const std::string& bindAddress,
                                                         double peerTimeoutSeconds, int in, int out,
                                                         std::optional<net::Secret> given) {
  std::unique_ptr<ControlLink> link(new ControlLink(in, out));
  Result<net::Secret> secret = net::Secret{};
  if (given) {
    secret = *given;
  } else {
    std::string line;
    const bool read = readLine(in, line);
    auto command = net::parseControlCommand(line);
    std::fill(line.begin(), line.end(), '\0');
    if (!read || !command || command->kind != net::ControlCommand::Kind::Secret) {
      return makeError("--control: the first line on stdin must be the run secret");
    }
    secret = net::secretFromHex(command->secretHex);
    std::fill(command->secretHex.begin(), command->secretHex.end(), '\0');
    if (!secret) return secret.error();
  }
  link->host_ = host;
  link->selfIndex_ = hostIndex(application, host);
  if (link->selfIndex_ < 0) return makeError("no host '" + host + "' in the application");
  const app::Host& self = application.hosts[static_cast<std::size_t>(link->selfIndex_)];

  net::TransportOptions options;
  options.selfIndex = link->selfIndex_;
  for (const auto& h : application.hosts) options.hostNames.push_back(h.id);
  options.bindAddress = bindAddress.empty() ? self.address : bindAddress;
  options.secret = *secret;
  options.peerTimeoutSeconds = peerTimeoutSeconds;
  auto transport = net::Transport::listen(options);
  secret->fill(0);
  options.secret.fill(0);
  if (!transport) return makeError("host '" + host + "': " + transport.error().message);
  link->transport_ = std::move(*transport);

  // Which host runs each node; connections crossing this host's boundary.
  auto hostOf = [&](const std::string& node) {
    for (const auto& m : application.modules) {
      if (m.id == node) return hostIndex(application, app::effectiveHost(application, m.host));
    }
    for (const auto& f : application.filters) {
      if (f.id == node) return hostIndex(application, app::effectiveHost(application, f.host));
    }
    return -1;
  };
  for (std::size_t i = 0; i < application.connections.size(); ++i) {
    const auto& c = application.connections[i];
    const int from = hostOf(c.from.node), to = hostOf(c.to.node);
    const auto channel = static_cast<uint32_t>(i);
    if (from == link->selfIndex_ && to == link->selfIndex_) {
      link->localChannels_.push_back(channel);
    } else if (from == link->selfIndex_ || to == link->selfIndex_) {
      net::RemoteConnection r{channel, c, from == link->selfIndex_ ? to : from,
                              from == link->selfIndex_};
      link->remote_.push_back(r);
      link->transport_->addConnection(r);
    }
  }
  link->send(net::ControlEvent::listening(link->transport_->port()));
  std::thread([fd = in, host, inbox = link->inbox_] { readLoop(fd, host, inbox); }).detach();
  return link;
}

Result<int> ControlLink::connectBack(const std::string& address, const net::Secret& secret,
                                     int hostIndex) {
  const auto colon = address.rfind(':');
  if (colon == std::string::npos) return makeError("--control-connect needs ADDRESS:PORT");
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(std::atoi(address.c_str() + colon + 1)));
  if (inet_pton(AF_INET, address.substr(0, colon).c_str(), &addr.sin_addr) != 1) {
    return makeError("--control-connect: '" + address + "' is not IPv4:PORT");
  }
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0 || connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    const int err = errno;
    if (fd >= 0) close(fd);
    return makeError("cannot reach the launcher at " + address + ": " + std::strerror(err));
  }
  std::string line;
  const bool read = readLine(fd, line);
  const auto nonce = net::parseControlCommand(line);
  if (!read || !nonce || nonce->kind != net::ControlCommand::Kind::Nonce) {
    close(fd);
    return makeError("the launcher at " + address + " did not send its nonce");
  }
  const std::string hello = net::toLine(net::ControlEvent::hello(
                                hostIndex, net::controlProof(secret, hostIndex, nonce->nonceHex))) +
                            "\n";
  if (write(fd, hello.data(), hello.size()) != static_cast<ssize_t>(hello.size())) {
    close(fd);
    return makeError("the launcher at " + address + " closed the control channel");
  }
  return fd;
}

ControlLink::~ControlLink() {
  if (transport_) transport_->stop();
  // The reader ends at end of input (the launcher closes our stdin when the run is over); it
  // holds the inbox, not this object.
}

void ControlLink::readLoop(int fd, const std::string& host, const std::shared_ptr<Inbox>& inbox) {
  std::string line;
  while (readLine(fd, line)) {
    auto command = net::parseControlCommand(line);
    if (!command) {
      run::logWarning("vrflow-daemon (host " + host +
                      "): ignored a line of the launcher: " + command.error().message);
      continue;
    }
    // Answered here, at once, whatever the main thread is doing: the launcher kills a daemon
    // that does not (a frozen one) instead of waiting for it.
    if (command->kind == Kind::Stop) {
      sendOn(*inbox, net::ControlEvent::bare(net::ControlEvent::Kind::Stopping));
    }
    std::lock_guard lock(inbox->mutex);
    inbox->commands.push_back(std::move(*command));
    inbox->changed.notify_all();
  }
  std::lock_guard lock(inbox->mutex);
  inbox->commands.push_back(net::ControlCommand::bare(Kind::End));
  inbox->changed.notify_all();
}

std::optional<net::ControlCommand> ControlLink::next(double seconds) {
  Inbox& inbox = *inbox_;
  std::unique_lock lock(inbox.mutex);
  if (seconds < 0) {
    inbox.changed.wait(lock, [&] { return !inbox.commands.empty(); });
  } else if (!inbox.changed.wait_for(lock, std::chrono::duration<double>(seconds),
                                     [&] { return !inbox.commands.empty(); })) {
    return std::nullopt;
  }
  net::ControlCommand command = inbox.commands.front();
  if (command.kind != Kind::End) inbox.commands.pop_front();  // end of input stays visible
  return command;
}

void ControlLink::send(const net::ControlEvent& event) {
  sendOn(*inbox_, event);
}

void ControlLink::sendOn(Inbox& inbox, const net::ControlEvent& event) {
  std::lock_guard lock(inbox.writeMutex);
  const int fd = inbox.out;
  std::string text = net::toLine(event) + "\n";
  const char* p = text.data();
  std::size_t left = text.size();
  while (left > 0) {
    const ssize_t n = write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // the launcher is gone; poll() sees the end of input
    p += n;
    left -= static_cast<std::size_t>(n);
  }
}

void ControlLink::configure(daemon::DaemonOptions& options) {
  options.transport = transport_.get();
  options.remote = remote_;
  options.connectionChannels = localChannels_;
}

Status ControlLink::ready() {
  std::vector<net::PeerAddress> peers;
  while (true) {
    const net::ControlCommand command = *next(-1);
    if (command.kind == Kind::Connect) break;
    if (command.kind == Kind::End || command.kind == Kind::Stop) {
      return stoppedBeforeStart(command);
    }
    if (command.kind == Kind::Peer) {
      peers.push_back({command.peerIndex, command.peerAddress, command.peerPort});
    }
  }
  if (auto status = transport_->connectPeers(peers); !status) {
    run::logError("vrflow-daemon (host " + host_ +
                  "): cannot link to the other hosts: " + status.error().message);
    send(net::ControlEvent::error(status.error().message));
    return status;
  }
  send(net::ControlEvent::bare(net::ControlEvent::Kind::Connected));
  while (true) {
    const net::ControlCommand command = *next(-1);
    if (command.kind == Kind::Go) return {};
    // "clock T": the launcher aligns this host's clock with its own (--trace).
    if (command.kind == Kind::Clock) {
      const auto now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                           std::chrono::steady_clock::now().time_since_epoch())
                           .count();
      send(net::ControlEvent::clock(command.clockNs, now));
      continue;
    }
    if (command.kind == Kind::End || command.kind == Kind::Stop) {
      return stoppedBeforeStart(command);
    }
  }
}

Status ControlLink::stoppedBeforeStart(const net::ControlCommand& command) {
  stopped_ = true;
  const std::string why = command.kind == Kind::Stop
                              ? "stopped by the launcher before the start"
                              : "the launcher closed the control channel before the start";
  run::logWarning("vrflow-daemon (host " + host_ + "): " + why);
  return makeError(why);
}

std::optional<run::RunOutcome> ControlLink::poll() {
  if (auto fatal = transport_->fatalError(); !fatal.empty()) {
    return run::RunOutcome{run::kExitRunFailed, "failed", fatal};
  }
  const auto command = next(0);
  if (!command) return std::nullopt;
  if (command->kind == Kind::Stop || command->kind == Kind::End) stopped_ = true;
  if (command->kind == Kind::Stop)
    return run::RunOutcome{run::kExitInterrupted, "stopped", "stopped by the launcher"};
  if (command->kind == Kind::End)
    return run::RunOutcome{run::kExitInterrupted, "stopped", "the launcher went away"};
  return std::nullopt;
}

void ControlLink::failing(const run::RunOutcome& outcome) {
  // The cause goes to the launcher now, before the modules are stopped; their last lines and
  // this host's report follow as usual.
  send(net::ControlEvent::finished(outcome.exitCode, outcome.status, outcome.error));
  finishedSent_ = true;
}

std::vector<std::string> ControlLink::drain(const run::RunOutcome& outcome) {
  // The modules' last lines were sent (the supervisor read their pipes to the end): what was
  // dropped of them is said before this host's end.
  for (const auto& dropped : takeDropped()) send(dropped);
  if (!finishedSent_) {
    send(net::ControlEvent::finished(outcome.exitCode, outcome.status, outcome.error));
  }
  std::vector<std::string> warnings;
  // Keep routing (messages for the other hosts) until the launcher says every host is done.
  while (!stopped_) {
    const auto command = next(0.05);
    if (!command) continue;
    if (command->kind == Kind::Quit) {
      warnings = settle();
      if (!stopped_) transport_->finish(2.0);
      break;
    }
    if (command->kind == Kind::Stop || command->kind == Kind::End) stopped_ = true;
  }
  if (stopped_) transport_->finish(0.5);  // say bye, so that peers do not log a lost link
  transport_->stop();
  return warnings;
}

std::vector<std::string> ControlLink::settle() {
  // Every host's modules have ended, but their last messages may still be on the way: a peer
  // says "finished" as soon as its modules exit, and what they sent last crosses the link
  // after. Wait until each connection is closed by its sender and what came before the close
  // is routed here, so that the report counts every message sent, as on one host.
  constexpr double kSettleSeconds = 10;
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::string> open;
  while (true) {
    open = transport_->settle(0.05);
    if (open.empty() || !transport_->fatalError().empty()) break;
    const auto command = next(0);
    if (command && (command->kind == Kind::Stop || command->kind == Kind::End)) {
      stopped_ = true;
      return {};
    }
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
        kSettleSeconds) {
      break;
    }
  }
  if (open.empty()) return {};
  std::string names;
  for (const auto& c : open) names += (names.empty() ? "" : ", ") + c;
  const auto fatal = transport_->fatalError();
  return {"connection(s) crossing hosts not closed after every host finished (" + names +
          "): " + (fatal.empty() ? "still open after 10 s" : fatal) +
          "; the report may miss their last messages"};
}

void ControlLink::trace(const std::string& json) {
  send(net::ControlEvent::payload(net::ControlEvent::Kind::Trace, json));
}

void ControlLink::stats(const std::string& json) {
  // The links' counters join the modules' and connections'.
  std::string links = "[";
  for (const auto& l : transport_->linkStats()) {
    if (links.size() > 1) links += ",";
    links += "{\"peer\":" + std::to_string(l.peer) +
             ",\"messages_sent\":" + std::to_string(l.messagesSent) +
             ",\"bytes_sent\":" + std::to_string(l.bytesSent) +
             ",\"messages_received\":" + std::to_string(l.messagesReceived) +
             ",\"bytes_received\":" + std::to_string(l.bytesReceived) + "}";
  }
  links += "]";
  if (json.empty() || json.back() != '}') return;
  send(net::ControlEvent::payload(net::ControlEvent::Kind::Stats,
                                  json.substr(0, json.size() - 1) + ",\"links\":" + links + "}"));
}

void ControlLink::event(const std::string& line) {
  send(net::ControlEvent::payload(net::ControlEvent::Kind::Event, line));
}

std::vector<net::ControlEvent> ControlLink::takeDropped() {
  std::vector<net::ControlEvent> events;
  std::lock_guard lock(budget_.mutex);
  for (auto& [module, count] : budget_.dropped) {
    if (count > 0) events.push_back(net::ControlEvent::droppedLines(module, count));
  }
  budget_.dropped.clear();
  return events;
}

void ControlLink::output(const std::string& module, std::string_view text) {
  std::vector<net::ControlEvent> events;
  {
    std::lock_guard lock(budget_.mutex);
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - budget_.refilled).count();
    budget_.refilled = now;
    budget_.lines =
        std::min(2 * kOutputLinesPerSecond, budget_.lines + seconds * kOutputLinesPerSecond);
    budget_.bytes =
        std::min(2 * kOutputBytesPerSecond, budget_.bytes + seconds * kOutputBytesPerSecond);
    const auto size = static_cast<double>(text.size());
    if (budget_.lines < 1 || budget_.bytes < size) {
      ++budget_.dropped[module];
      return;
    }
    budget_.lines -= 1;
    budget_.bytes -= size;
    for (auto& [id, count] : budget_.dropped) {
      if (count > 0) events.push_back(net::ControlEvent::droppedLines(id, count));
    }
    budget_.dropped.clear();
  }
  events.push_back(net::ControlEvent::output(module, std::string(text)));
  for (const auto& e : events) send(e);
}

void ControlLink::report(const std::string& json) {
  send(net::ControlEvent::payload(net::ControlEvent::Kind::Report, json));
}

}  // namespace vrflow::tools
