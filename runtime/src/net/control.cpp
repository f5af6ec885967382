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
    if (args != 1 || extra) return malformed("expected 'secret HEX'", line);
    c.kind = ControlCommand::Kind::Secret;
    c.secretHex = std::string(s.words[1]);
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

std::string finishedLine(int exitCode, const std::string& status, const std::string& error) {
  return "finished " + std::to_string(exitCode) + " " + status + " " + error;
}

}  // namespace vrflow::net
