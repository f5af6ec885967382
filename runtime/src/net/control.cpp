#include "vrflow/net/control.hpp"

#include <algorithm>
#include <charconv>
#include <vector>

namespace vrflow::net {
namespace {

// The line's words, split at single spaces; `rest` is what follows the first `count` words
// (after one space), for lines whose last field is free text.
struct Split {
  std::vector<std::string_view> words;
  std::string_view rest;
  bool hasRest = false;
};

Split split(std::string_view line, std::size_t count) {
  Split s;
  std::size_t at = 0;
  while (s.words.size() < count && at <= line.size()) {
    const std::size_t space = line.find(' ', at);
    if (space == std::string_view::npos) {
      s.words.push_back(line.substr(at));
      return s;
    }
    s.words.push_back(line.substr(at, space - at));
    at = space + 1;
  }
  s.rest = line.substr(std::min(at, line.size()));
  s.hasRest = true;
  return s;
}

template <typename T>
bool number(std::string_view text, T& value) {
  if (text.empty()) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc() && end == text.data() + text.size();
}

bool port(std::string_view text, uint16_t& value) {
  return number(text, value) && value != 0;
}

// Echoes at most 80 bytes of a line into an error, printable ASCII only.
Error malformed(std::string_view what, std::string_view line) {
  std::string shown;
  for (const char c : line.substr(0, 80)) {
    shown += c >= 0x20 && c < 0x7f ? c : '?';
  }
  if (line.size() > 80) shown += "... (" + std::to_string(line.size()) + " bytes)";
  return makeError(std::string(what) + ": '" + shown + "'");
}

}  // namespace

Result<ControlCommand> parseControlCommand(std::string_view line) {
  ControlCommand c;
  const Split s = split(line, 4);
  const std::string_view word = s.words.front();
  const std::size_t args = s.words.size() - 1;
  const bool extra = s.hasRest;  // more words than any command takes
  auto bare = [&](ControlCommand::Kind kind) -> Result<ControlCommand> {
    if (args != 0 || extra) return malformed("control command takes no argument", line);
    c.kind = kind;
    return c;
  };
  if (word == "eof") return bare(ControlCommand::Kind::End);
  if (word == "connect") return bare(ControlCommand::Kind::Connect);
  if (word == "go") return bare(ControlCommand::Kind::Go);
  if (word == "stop") return bare(ControlCommand::Kind::Stop);
  if (word == "quit") return bare(ControlCommand::Kind::Quit);
  if (word == "secret") {
    if (args != 1 || extra || s.words[1].empty()) return malformed("expected 'secret HEX'", line);
    c.kind = ControlCommand::Kind::Secret;
    c.secretHex = std::string(s.words[1]);
    return c;
  }
  if (word == "nonce") {
    if (args != 1 || extra || s.words[1].empty()) return malformed("expected 'nonce HEX'", line);
    c.kind = ControlCommand::Kind::Nonce;
    c.nonceHex = std::string(s.words[1]);
    return c;
  }
  if (word == "clock") {
    if (args != 1 || extra || !number(s.words[1], c.clockNs)) {
      return malformed("expected 'clock NANOSECONDS'", line);
    }
    c.kind = ControlCommand::Kind::Clock;
    return c;
  }
  if (word == "peer") {
    if (args != 3 || extra || !number(s.words[1], c.peerIndex) || c.peerIndex < 0 ||
        s.words[2].empty() || !port(s.words[3], c.peerPort)) {
      return malformed("expected 'peer INDEX ADDRESS PORT'", line);
    }
    c.kind = ControlCommand::Kind::Peer;
    c.peerAddress = std::string(s.words[2]);
    return c;
  }
  return malformed("unknown control command", line);
}

Result<ControlEvent> parseControlEvent(std::string_view line) {
  ControlEvent e;
  const Split one = split(line, 1);
  const std::string_view word = one.words.front();
  auto bare = [&](ControlEvent::Kind kind) -> Result<ControlEvent> {
    if (one.hasRest) return malformed("control event takes no argument", line);
    e.kind = kind;
    return e;
  };
  auto payload = [&](ControlEvent::Kind kind) -> Result<ControlEvent> {
    if (!one.hasRest || one.rest.empty()) return malformed("control event without its text", line);
    e.kind = kind;
    e.text = std::string(one.rest);
    return e;
  };
  if (word == "connected") return bare(ControlEvent::Kind::Connected);
  if (word == "stopping") return bare(ControlEvent::Kind::Stopping);
  if (word == "error") return payload(ControlEvent::Kind::Error);
  if (word == "report") return payload(ControlEvent::Kind::Report);
  if (word == "stats") return payload(ControlEvent::Kind::Stats);
  if (word == "trace") return payload(ControlEvent::Kind::Trace);
  if (word == "event") return payload(ControlEvent::Kind::Event);
  if (word == "hello") {
    const Split s = split(line, 3);
    if (s.words.size() != 3 || s.hasRest || !number(s.words[1], e.hostIndex) || e.hostIndex < 0 ||
        s.words[2].empty()) {
      return malformed("expected 'hello INDEX PROOF'", line);
    }
    e.kind = ControlEvent::Kind::Hello;
    e.text = std::string(s.words[2]);
    return e;
  }
  if (word == "listening") {
    const Split s = split(line, 2);
    if (s.words.size() != 2 || s.hasRest || !port(s.words[1], e.port)) {
      return malformed("expected 'listening PORT'", line);
    }
    e.kind = ControlEvent::Kind::Listening;
    return e;
  }
  if (word == "clock") {
    const Split s = split(line, 3);
    if (s.words.size() != 3 || s.hasRest || !number(s.words[1], e.clockSentNs) ||
        !number(s.words[2], e.clockDaemonNs)) {
      return malformed("expected 'clock SENT DAEMON'", line);
    }
    e.kind = ControlEvent::Kind::Clock;
    return e;
  }
  if (word == "output") {
    // "output MODULE TEXT": the text is what the module printed, possibly empty.
    const Split s = split(line, 2);
    if (s.words.size() != 2 || !s.hasRest || s.words[1].empty()) {
      return malformed("expected 'output MODULE TEXT'", line);
    }
    e.kind = ControlEvent::Kind::Output;
    e.module = std::string(s.words[1]);
    e.text = std::string(s.rest);
    return e;
  }
  if (word == "dropped") {
    const Split s = split(line, 3);
    if (s.words.size() != 3 || s.hasRest || s.words[1].empty() || !number(s.words[2], e.dropped)) {
      return malformed("expected 'dropped MODULE COUNT'", line);
    }
    e.kind = ControlEvent::Kind::Dropped;
    e.module = std::string(s.words[1]);
    return e;
  }
  if (word == "finished") {
    // "finished CODE STATUS ERROR": the error is free text, possibly empty.
    const Split s = split(line, 3);
    if (s.words.size() != 3 || !number(s.words[1], e.exitCode) || s.words[2].empty()) {
      return malformed("expected 'finished CODE STATUS ERROR'", line);
    }
    e.kind = ControlEvent::Kind::Finished;
    e.status = std::string(s.words[2]);
    e.text = std::string(s.rest);
    return e;
  }
  return malformed("unknown control event", line);
}

ControlCommand ControlCommand::bare(Kind kind) {
  ControlCommand c;
  c.kind = kind;
  return c;
}

ControlCommand ControlCommand::secret(std::string hex) {
  ControlCommand c = bare(Kind::Secret);
  c.secretHex = std::move(hex);
  return c;
}

ControlCommand ControlCommand::nonce(std::string hex) {
  ControlCommand c = bare(Kind::Nonce);
  c.nonceHex = std::move(hex);
  return c;
}

ControlCommand ControlCommand::peer(int index, std::string address, uint16_t port) {
  ControlCommand c = bare(Kind::Peer);
  c.peerIndex = index;
  c.peerAddress = std::move(address);
  c.peerPort = port;
  return c;
}

ControlCommand ControlCommand::clock(int64_t ns) {
  ControlCommand c = bare(Kind::Clock);
  c.clockNs = ns;
  return c;
}

std::string toLine(const ControlCommand& command) {
  using Kind = ControlCommand::Kind;
  switch (command.kind) {
    case Kind::Secret:
      return "secret " + command.secretHex;
    case Kind::Nonce:
      return "nonce " + command.nonceHex;
    case Kind::Peer:
      return "peer " + std::to_string(command.peerIndex) + " " + command.peerAddress + " " +
             std::to_string(command.peerPort);
    case Kind::Connect:
      return "connect";
    case Kind::Clock:
      return "clock " + std::to_string(command.clockNs);
    case Kind::Go:
      return "go";
    case Kind::Stop:
      return "stop";
    case Kind::Quit:
      return "quit";
    case Kind::End:
      break;
  }
  return "eof";
}

ControlEvent ControlEvent::bare(Kind kind) {
  ControlEvent e;
  e.kind = kind;
  return e;
}

ControlEvent ControlEvent::hello(int index, std::string proof) {
  ControlEvent e = bare(Kind::Hello);
  e.hostIndex = index;
  e.text = std::move(proof);
  return e;
}

ControlEvent ControlEvent::listening(uint16_t port) {
  ControlEvent e = bare(Kind::Listening);
  e.port = port;
  return e;
}

ControlEvent ControlEvent::error(std::string text) {
  return payload(Kind::Error, std::move(text));
}

ControlEvent ControlEvent::finished(int exitCode, std::string status, std::string error) {
  ControlEvent e = bare(Kind::Finished);
  e.exitCode = exitCode;
  e.status = std::move(status);
  e.text = std::move(error);
  return e;
}

ControlEvent ControlEvent::payload(Kind kind, std::string json) {
  ControlEvent e = bare(kind);
  e.text = std::move(json);
  return e;
}

ControlEvent ControlEvent::clock(int64_t sentNs, int64_t daemonNs) {
  ControlEvent e = bare(Kind::Clock);
  e.clockSentNs = sentNs;
  e.clockDaemonNs = daemonNs;
  return e;
}

ControlEvent ControlEvent::output(std::string module, std::string text) {
  ControlEvent e = bare(Kind::Output);
  e.module = std::move(module);
  e.text = std::move(text);
  return e;
}

ControlEvent ControlEvent::droppedLines(std::string module, uint64_t count) {
  ControlEvent e = bare(Kind::Dropped);
  e.module = std::move(module);
  e.dropped = count;
  return e;
}

std::string toLine(const ControlEvent& event) {
  using Kind = ControlEvent::Kind;
  // Free text ends the line: a newline in it would start a line of its own.
  std::string text = event.text;
  std::replace(text.begin(), text.end(), '\n', ' ');
  switch (event.kind) {
    case Kind::Hello:
      return "hello " + std::to_string(event.hostIndex) + " " + text;
    case Kind::Listening:
      return "listening " + std::to_string(event.port);
    case Kind::Connected:
      return "connected";
    case Kind::Stopping:
      return "stopping";
    case Kind::Error:
      return "error " + text;
    case Kind::Finished:
      return "finished " + std::to_string(event.exitCode) + " " + event.status + " " + text;
    case Kind::Report:
      return "report " + text;
    case Kind::Stats:
      return "stats " + text;
    case Kind::Trace:
      return "trace " + text;
    case Kind::Event:
      return "event " + text;
    case Kind::Clock:
      return "clock " + std::to_string(event.clockSentNs) + " " +
             std::to_string(event.clockDaemonNs);
    case Kind::Output:
      return "output " + event.module + " " + text;
    case Kind::Dropped:
      return "dropped " + event.module + " " + std::to_string(event.dropped);
  }
  return {};
}

}  // namespace vrflow::net
