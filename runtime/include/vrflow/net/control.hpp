#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "vrflow/base/result.hpp"

// The control channel between the launcher and each daemon: one command or event per line
// (docs/transport.md, "Launcher and daemons"). Both ends parse with these functions, so that a
// line means one thing, and a malformed line is an error rather than a guess.
namespace vrflow::net {

/// A line from the launcher to a daemon.
struct ControlCommand {
  enum class Kind { Secret, Peer, Connect, Clock, Go, Stop, Quit, End };
  Kind kind = Kind::End;
  std::string secretHex;    ///< Secret: the 64 hex digits (checked by secretFromHex)
  int peerIndex = -1;       ///< Peer: the host's index in the application file
  std::string peerAddress;  ///< Peer: its IPv4 address, as written
  uint16_t peerPort = 0;    ///< Peer: 1 to 65535
  int64_t clockNs = 0;      ///< Clock: the launcher's steady clock, echoed back
};

/// Parses a launcher's line ("eof", the reader's end of input, is End); an error naming the
/// line for an unknown command or malformed arguments.
Result<ControlCommand> parseControlCommand(std::string_view line);

/// A line from a daemon to the launcher.
struct ControlEvent {
  enum class Kind { Listening, Connected, Stopping, Error, Finished, Report, Stats, Trace, Clock };
  Kind kind = Kind::Connected;
  uint16_t port = 0;   ///< Listening: 1 to 65535
  int exitCode = 0;    ///< Finished: the host's exit status
  std::string status;  ///< Finished: one word ("ok", "failed", "stopped", ...)
  std::string text;    ///< Error/Finished: the message; Report/Stats/Trace: the JSON
  int64_t clockSentNs = 0, clockDaemonNs = 0;  ///< Clock: the launcher's time echoed, the daemon's
};

/// Parses a daemon's line; an error naming the line for an unknown event or malformed arguments.
Result<ControlEvent> parseControlEvent(std::string_view line);

/// The "finished CODE STATUS ERROR" line (the inverse of parseControlEvent for Finished).
std::string finishedLine(int exitCode, const std::string& status, const std::string& error);

}  // namespace vrflow::net
