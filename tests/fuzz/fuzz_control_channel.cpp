// libFuzzer target: the control channel between the launcher and the daemons
// (runtime/src/net/control.cpp) on arbitrary bytes, cut into lines as both ends read them. Every
// line goes through both parsers (the daemon's for commands, the launcher's for events). Beyond
// "no crash, no sanitizer report", it checks what the parsers promise: parsed fields are in
// range, a parsed line written back parses to the same values, and an error echoes a bounded
// part of the line (output amplification).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "vrflow/net/control.hpp"

namespace {

void check(bool condition) {
  if (!condition) __builtin_trap();
}

using vrflow::net::ControlCommand;
using vrflow::net::ControlEvent;

void commandLine(std::string_view line) {
  auto command = vrflow::net::parseControlCommand(line);
  if (!command) {
    check(command.error().message.size() < 200);
    return;
  }
  switch (command->kind) {
    case ControlCommand::Kind::Peer: {
      check(command->peerIndex >= 0 && command->peerPort != 0);
      check(!command->peerAddress.empty() && command->peerAddress.find(' ') == std::string::npos);
      auto reparsed = vrflow::net::parseControlCommand(vrflow::net::toLine(*command));
      check(reparsed.ok() && reparsed->peerIndex == command->peerIndex &&
            reparsed->peerAddress == command->peerAddress &&
            reparsed->peerPort == command->peerPort);
      break;
    }
    case ControlCommand::Kind::Clock: {
      auto reparsed = vrflow::net::parseControlCommand(vrflow::net::toLine(*command));
      check(reparsed.ok() && reparsed->clockNs == command->clockNs);
      break;
    }
    case ControlCommand::Kind::Secret:
    case ControlCommand::Kind::Nonce:
      check(line == vrflow::net::toLine(*command));
      break;
    default:
      check(line == "connect" || line == "go" || line == "stop" || line == "quit" || line == "eof");
      break;
  }
}

void eventLine(std::string_view line) {
  auto event = vrflow::net::parseControlEvent(line);
  if (!event) {
    check(event.error().message.size() < 200);
    return;
  }
  switch (event->kind) {
    case ControlEvent::Kind::Listening:
      check(event->port != 0);
      break;
    case ControlEvent::Kind::Finished: {
      check(!event->status.empty() && event->status.find(' ') == std::string::npos);
      auto reparsed = vrflow::net::parseControlEvent(vrflow::net::toLine(*event));
      check(reparsed.ok() && reparsed->kind == ControlEvent::Kind::Finished &&
            reparsed->exitCode == event->exitCode && reparsed->status == event->status &&
            reparsed->text == event->text);
      break;
    }
    case ControlEvent::Kind::Output:
    case ControlEvent::Kind::Dropped: {
      // A module's line comes back whole, spaces and all; its module id has none.
      check(!event->module.empty() && event->module.find(' ') == std::string::npos);
      auto reparsed = vrflow::net::parseControlEvent(vrflow::net::toLine(*event));
      check(reparsed.ok() && reparsed->kind == event->kind && reparsed->module == event->module &&
            reparsed->text == event->text && reparsed->dropped == event->dropped);
      break;
    }
    case ControlEvent::Kind::Error:
    case ControlEvent::Kind::Report:
    case ControlEvent::Kind::Stats:
    case ControlEvent::Kind::Trace:
    case ControlEvent::Kind::Event:
      check(!event->text.empty() && line.size() > event->text.size() &&
            line.substr(line.size() - event->text.size()) == event->text);
      break;
    default:
      break;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  std::string_view stream(reinterpret_cast<const char*>(data), size);
  while (!stream.empty()) {
    const std::size_t eol = stream.find('\n');
    const std::string_view line = stream.substr(0, eol);
    commandLine(line);
    eventLine(line);
    if (eol == std::string_view::npos) break;
    stream.remove_prefix(eol + 1);
  }
  return 0;
}
