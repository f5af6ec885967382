// The launcher↔daemon control channel's codec (vrflow/net/control.hpp): every line one side
// writes the other reads back to the same values, and malformed lines are errors naming them.
#include "vrflow/net/control.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace vrflow::net {
namespace {

using CommandKind = ControlCommand::Kind;
using EventKind = ControlEvent::Kind;

ControlCommand reparsed(const ControlCommand& command) {
  auto parsed = parseControlCommand(toLine(command));
  EXPECT_TRUE(parsed.ok()) << toLine(command) << ": " << parsed.error().message;
  return parsed.ok() ? *parsed : ControlCommand{};
}

ControlEvent reparsed(const ControlEvent& event) {
  auto parsed = parseControlEvent(toLine(event));
  EXPECT_TRUE(parsed.ok()) << toLine(event) << ": " << parsed.error().message;
  return parsed.ok() ? *parsed : ControlEvent{};
}

TEST(ControlCodec, EveryCommandReadsBackAsWritten) {
  EXPECT_EQ(toLine(ControlCommand::peer(2, "127.0.0.3", 4711)), "peer 2 127.0.0.3 4711");
  const ControlCommand peer = reparsed(ControlCommand::peer(2, "127.0.0.3", 4711));
  EXPECT_EQ(peer.kind, CommandKind::Peer);
  EXPECT_EQ(peer.peerIndex, 2);
  EXPECT_EQ(peer.peerAddress, "127.0.0.3");
  EXPECT_EQ(peer.peerPort, 4711);
  EXPECT_EQ(reparsed(ControlCommand::secret(std::string(64, 'a'))).secretHex, std::string(64, 'a'));
  EXPECT_EQ(reparsed(ControlCommand::nonce("0badc0de")).nonceHex, "0badc0de");
  EXPECT_EQ(reparsed(ControlCommand::clock(-5)).clockNs, -5);
  for (const auto kind :
       {CommandKind::Connect, CommandKind::Go, CommandKind::Stop, CommandKind::Quit}) {
    EXPECT_EQ(reparsed(ControlCommand::bare(kind)).kind, kind)
        << toLine(ControlCommand::bare(kind));
  }
}

TEST(ControlCodec, EveryEventReadsBackAsWritten) {
  EXPECT_EQ(reparsed(ControlEvent::listening(40000)).port, 40000);
  EXPECT_EQ(reparsed(ControlEvent::bare(EventKind::Connected)).kind, EventKind::Connected);
  EXPECT_EQ(reparsed(ControlEvent::bare(EventKind::Stopping)).kind, EventKind::Stopping);
  EXPECT_EQ(reparsed(ControlEvent::error("host 'b': refused")).text, "host 'b': refused");
  const ControlEvent hello = reparsed(ControlEvent::hello(3, "abcdef"));
  EXPECT_EQ(hello.kind, EventKind::Hello);
  EXPECT_EQ(hello.hostIndex, 3);
  EXPECT_EQ(hello.text, "abcdef");
  const ControlEvent clock = reparsed(ControlEvent::clock(10, 20));
  EXPECT_EQ(clock.clockSentNs, 10);
  EXPECT_EQ(clock.clockDaemonNs, 20);
  for (const auto kind :
       {EventKind::Report, EventKind::Stats, EventKind::Trace, EventKind::Event}) {
    const ControlEvent payload = reparsed(ControlEvent::payload(kind, "{\"a\": [1, 2]}"));
    EXPECT_EQ(payload.kind, kind);
    EXPECT_EQ(payload.text, "{\"a\": [1, 2]}");
  }
}

TEST(ControlCodec, FinishedKeepsAnEmptyOrSpacedErrorWhole) {
  const ControlEvent ok = reparsed(ControlEvent::finished(0, "ok", ""));
  EXPECT_EQ(ok.kind, EventKind::Finished);
  EXPECT_EQ(ok.exitCode, 0);
  EXPECT_EQ(ok.status, "ok");
  EXPECT_EQ(ok.text, "");
  const ControlEvent failed =
      reparsed(ControlEvent::finished(1, "failed", "module 'a' exited with status 3"));
  EXPECT_EQ(failed.exitCode, 1);
  EXPECT_EQ(failed.status, "failed");
  EXPECT_EQ(failed.text, "module 'a' exited with status 3");
}

TEST(ControlCodec, ModuleOutputKeepsItsTextAsPrintedEvenEmptyOrSpaced) {
  EXPECT_EQ(toLine(ControlEvent::output("sim", "  step 3 done ")), "output sim   step 3 done ");
  const ControlEvent spaced = reparsed(ControlEvent::output("sim", "  step 3 done "));
  EXPECT_EQ(spaced.kind, EventKind::Output);
  EXPECT_EQ(spaced.module, "sim");
  EXPECT_EQ(spaced.text, "  step 3 done ");
  EXPECT_EQ(reparsed(ControlEvent::output("sim", "")).text, "");
  const ControlEvent dropped = reparsed(ControlEvent::droppedLines("sim", 12345678901ULL));
  EXPECT_EQ(dropped.kind, EventKind::Dropped);
  EXPECT_EQ(dropped.module, "sim");
  EXPECT_EQ(dropped.dropped, 12345678901ULL);
  for (const char* bad :
       {"output", "output sim", "dropped sim", "dropped sim -1", "dropped sim 3 x"}) {
    EXPECT_FALSE(parseControlEvent(bad).ok()) << bad;
  }
}

TEST(ControlCodec, ANewlineInFreeTextDoesNotStartALineOfItsOwn) {
  const std::string line = toLine(ControlEvent::finished(1, "failed", "first\nstop"));
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_EQ(reparsed(ControlEvent::payload(EventKind::Report, "{\n\"a\": 1\n}")).text,
            "{ \"a\": 1 }");
}

TEST(ControlCodec, MalformedCommandsAreErrorsNamingTheLine) {
  const std::vector<std::string> lines{"",
                                       "bogus",
                                       "go now",
                                       "secret",
                                       "secret a b",
                                       "nonce",
                                       "peer 1 127.0.0.1",
                                       "peer -1 127.0.0.1 80",
                                       "peer 1 127.0.0.1 0",
                                       "peer 1 127.0.0.1 65536",
                                       "peer x 127.0.0.1 80",
                                       "clock",
                                       "clock 12x",
                                       "listening 80"};
  for (const auto& line : lines) {
    auto parsed = parseControlCommand(line);
    ASSERT_FALSE(parsed.ok()) << "'" << line << "' parsed";
    EXPECT_NE(parsed.error().message.find("'" + line + "'"), std::string::npos)
        << parsed.error().message;
  }
}

TEST(ControlCodec, MalformedEventsAreErrorsNamingTheLine) {
  const std::vector<std::string> lines{"",
                                       "go",
                                       "connected now",
                                       "listening",
                                       "listening 0",
                                       "listening port",
                                       "error",
                                       "stats",
                                       "finished",
                                       "finished x ok oops",
                                       "finished 1",
                                       "hello",
                                       "hello -1 proof",
                                       "hello 1",
                                       "clock 1",
                                       "clock 1 2 3"};
  for (const auto& line : lines) {
    auto parsed = parseControlEvent(line);
    ASSERT_FALSE(parsed.ok()) << "'" << line << "' parsed";
    EXPECT_NE(parsed.error().message.find("'" + line + "'"), std::string::npos)
        << parsed.error().message;
  }
}

TEST(ControlCodec, AnErrorShowsABoundedPrintablePartOfTheLine) {
  const std::string line = "bogus\x01" + std::string(500, 'x');
  auto parsed = parseControlCommand(line);
  ASSERT_FALSE(parsed.ok());
  EXPECT_LT(parsed.error().message.size(), 200u);
  EXPECT_EQ(parsed.error().message.find('\x01'), std::string::npos);
}

}  // namespace
}  // namespace vrflow::net
