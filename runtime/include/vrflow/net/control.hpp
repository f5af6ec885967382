#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <cstdint>
#include <string>
#include <string_view>

#include "vrflow/base/result.hpp"

// The control channel between the launcher and each daemon: one command or event per line
// (docs/transport.md, "Launcher and daemons"). Both ends parse with these functions, so that a
// line means one thing, and a malformed line is an error rather than a guess.
namespace vrflow::net {

/// A line from the launcher to a daemon. Build one with the named constructors, write it with
/// toLine(), read it with parseControlCommand().
struct ControlCommand {
  enum class Kind { Secret, Nonce, Peer, Connect, Clock, Go, Stop, Quit, End };
  Kind kind = Kind::End;
  std::string secretHex;    ///< Secret: the 64 hex digits (checked by secretFromHex)
  std::string nonceHex;     ///< Nonce: the launcher's challenge (mpirun's control socket)
  int peerIndex = -1;       ///< Peer: the host's index in the application file
  std::string peerAddress;  ///< Peer: its IPv4 address, as written
  uint16_t peerPort = 0;    ///< Peer: 1 to 65535
  int64_t clockNs = 0;      ///< Clock: the launcher's steady clock, echoed back

  /// A command without arguments: Connect, Go, Stop, Quit (End is the reader's, never sent).
  static ControlCommand bare(Kind kind);
  /// "secret HEX": the first line on a daemon's stdin.
  static ControlCommand secret(std::string hex);
  /// "nonce HEX": the first line on a control socket (mpirun), answered by a Hello event.
  static ControlCommand nonce(std::string hex);
  /// "peer INDEX ADDRESS PORT": where the daemon of host INDEX listens.
  static ControlCommand peer(int index, std::string address, uint16_t port);
  /// "clock NANOSECONDS": the launcher's steady clock, to be echoed with the daemon's.
  static ControlCommand clock(int64_t ns);
};

/// Parses a launcher's line ("eof", the reader's end of input, is End); an error naming the
/// line for an unknown command or malformed arguments.
Result<ControlCommand> parseControlCommand(std::string_view line);

/// The line of `command`, without its newline (parseControlCommand's inverse).
std::string toLine(const ControlCommand& command);

/// A line from a daemon to the launcher. Build one with the named constructors, write it with
/// toLine(), read it with parseControlEvent().
struct ControlEvent {
  enum class Kind {
    Hello,
    Listening,
    Connected,
    Stopping,
    Error,
    Finished,
    Report,
    Stats,
    Trace,
    Event,
    Clock,
    Output,
    Dropped
  };
  Kind kind = Kind::Connected;
  int hostIndex = -1;  ///< Hello: the host the daemon serves
  uint16_t port = 0;   ///< Listening: 1 to 65535
  int exitCode = 0;    ///< Finished: the host's exit status
  std::string status;  ///< Finished: one word ("ok", "failed", "stopped", ...)
  /// Error/Finished: the message (one line); Report/Stats/Trace/Event: the JSON (one line);
  /// Hello: the proof (controlProof(), hex).
  std::string text;
  int64_t clockSentNs = 0, clockDaemonNs = 0;  ///< Clock: the launcher's time echoed, the daemon's
  std::string module;    ///< Output/Dropped: the id of the module that printed (no spaces)
  uint64_t dropped = 0;  ///< Dropped: how many of its lines were not forwarded

  /// An event without arguments: Connected, Stopping.
  static ControlEvent bare(Kind kind);
  /// "hello INDEX PROOF": the answer to a nonce (mpirun).
  static ControlEvent hello(int hostIndex, std::string proof);
  /// "listening PORT".
  static ControlEvent listening(uint16_t port);
  /// "error TEXT": the links could not be made.
  static ControlEvent error(std::string text);
  /// "finished CODE STATUS ERROR": this host's modules have ended.
  static ControlEvent finished(int exitCode, std::string status, std::string error);
  /// "report JSON", "stats JSON", "trace JSON" or "event JSON" (a line of the host's event
  /// stream, docs/events.md) (`kind` says which); newlines in `json` are
  /// written as spaces, which JSON allows between tokens (it holds none inside strings).
  static ControlEvent payload(Kind kind, std::string json);
  /// "clock SENT DAEMON": the launcher's time echoed, with the daemon's steady clock.
  static ControlEvent clock(int64_t sentNs, int64_t daemonNs);
  /// "output MODULE TEXT": a line module MODULE printed (docs/logs.md); TEXT may be empty.
  static ControlEvent output(std::string module, std::string text);
  /// "dropped MODULE COUNT": COUNT lines of MODULE were not forwarded (over the rate limit).
  static ControlEvent droppedLines(std::string module, uint64_t count);
};

/// Parses a daemon's line; an error naming the line for an unknown event or malformed arguments.
Result<ControlEvent> parseControlEvent(std::string_view line);

/// The line of `event`, without its newline (parseControlEvent's inverse).
std::string toLine(const ControlEvent& event);

}  // namespace vrflow::net
