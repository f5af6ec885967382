#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstring>
#include <future>
#include <memory>
#include <optional>
#include <thread>

#include "daemon/graph.hpp"
#include "vrflow/ipc/segment.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/byte_sink.hpp"
#include "vrflow/message/empty_message.hpp"
#include "vrflow/net/transport.hpp"

namespace vrflow::net {
namespace {

TransportOptions optionsFor(int index, const Secret& secret) {
  TransportOptions o;
  o.selfIndex = index;
  o.hostNames = {"a", "b"};
  o.bindAddress = index == 0 ? "127.0.0.1" : "127.0.0.2";
  o.secret = secret;
  o.connectSeconds = 3;
  o.handshakeSeconds = 5;
  return o;
}

RemoteConnection channel0(bool outgoing) {
  RemoteConnection r;
  r.channel = 0;
  r.connection.from = {"p", "out"};
  r.connection.to = {"q", "in"};
  r.connection.capacity = 4;
  r.peer = outgoing ? 1 : 0;
  r.outgoing = outgoing;
  return r;
}

// Reads from a raw socket until the peer closes it (true) or 10 s pass (false).
bool closedByPeer(int fd) {
  char buffer[256];
  for (int i = 0; i < 100; ++i) {
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, 100) == 1) {
      const ssize_t n = read(fd, buffer, sizeof buffer);
      if (n <= 0) return true;
    }
  }
  return false;
}

int rawConnect(uint16_t port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  inet_pton(AF_INET, "127.0.0.2", &addr.sin_addr);
  EXPECT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  return fd;
}

class Collect final : public daemon::Sink {
 public:
  bool hasSpace() const override { return true; }
  void push(daemon::MessageRef message) override { messages.push_back(std::move(message)); }
  void close() override {}
  std::vector<daemon::MessageRef> messages;
};

// Transports a (127.0.0.1) and b (127.0.0.2), each with a segment of `segmentBytes`, sharing
// connection 0 (a sends, b receives), authenticated and linked to each other.
struct LinkedPair {
  std::unique_ptr<Transport> a, b;
  std::optional<ipc::Segment> segA, segB;
};

::testing::AssertionResult link(LinkedPair& pair, std::size_t segmentBytes) {
  const Secret secret = newSecret();
  auto a = Transport::listen(optionsFor(0, secret));
  auto b = Transport::listen(optionsFor(1, secret));
  if (!a.ok() || !b.ok()) return ::testing::AssertionFailure() << "listen failed";
  auto segA = ipc::Segment::create(segmentBytes, 0x7f000001);
  auto segB = ipc::Segment::create(segmentBytes, 0x7f000002);
  if (!segA.ok() || !segB.ok()) return ::testing::AssertionFailure() << "no segment";
  pair.a = std::move(*a);
  pair.b = std::move(*b);
  pair.segA.emplace(std::move(*segA));
  pair.segB.emplace(std::move(*segB));
  pair.a->attachSegment(*pair.segA);
  pair.b->attachSegment(*pair.segB);
  pair.a->addConnection(channel0(true));
  pair.b->addConnection(channel0(false));
  const std::vector<PeerAddress> peers{{0, "127.0.0.1", pair.a->port()},
                                       {1, "127.0.0.2", pair.b->port()}};
  auto linkB = std::async(std::launch::async, [&] { return pair.b->connectPeers(peers); });
  const bool linkedA = pair.a->connectPeers(peers).ok();
  if (!linkB.get().ok() || !linkedA) return ::testing::AssertionFailure() << "not linked";
  return ::testing::AssertionSuccess();
}

// An empty message with `stamps`, written into `segment`: its block handle.
uint64_t emptyMessageIn(ipc::Segment& segment, const msg::Stamps& stamps) {
  const auto bytes = msg::makeEmptyMessage(stamps);
  const uint64_t handle = segment.allocate(bytes.size());
  std::memcpy(segment.payload(handle), bytes.data(), bytes.size());
  segment.block(handle).used = bytes.size();
  return handle;
}

// What `transport` receives on connection 0 until the sender closes it (at most 10 s): true when
// it closed.
bool receiveUntilClosed(Transport& transport, Collect& received) {
  bool closed = false;
  for (int i = 0; i < 1000 && !closed; ++i) {
    transport.receive(0, received, closed);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return closed;
}

TEST(Transport, AuthenticatedPeersCarryAMessageIntoTheReceiversSharedMemory) {
  LinkedPair pair;
  ASSERT_TRUE(link(pair, 16 << 20));
  auto& a = pair.a;
  auto& b = pair.b;
  auto& segA = pair.segA;

  msg::Stamps stamps;
  stamps.iteration = 42;
  const uint64_t handle = emptyMessageIn(*segA, stamps);
  auto sink = a->makeSink(0);
  ASSERT_TRUE(sink->hasSpace());
  sink->push(daemon::MessageRef(&*segA, handle));
  sink->close();

  Collect received;
  ASSERT_TRUE(receiveUntilClosed(*b, received));
  ASSERT_EQ(received.messages.size(), 1u);
  auto view = received.messages[0].view();
  ASSERT_TRUE(view.ok());
  EXPECT_EQ(view->stamps().iteration, 42u);
  EXPECT_EQ(b->fatalError(), "");
  received.messages.clear();
  a->finish(2);
  b->finish(2);
  a->stop();
  b->stop();
}

TEST(Transport, SettleWaitsUntilWhatCameBeforeThePeersCloseIsRouted) {
  LinkedPair pair;
  ASSERT_TRUE(link(pair, 16 << 20));
  auto& a = pair.a;
  auto& b = pair.b;
  auto& segA = pair.segA;
  const std::vector<std::string> open{"p.out -> q.in"};
  EXPECT_EQ(a->settle(0), open);
  EXPECT_EQ(b->settle(0), open);

  const uint64_t handle = emptyMessageIn(*segA, msg::Stamps{});
  auto sink = a->makeSink(0);
  sink->push(daemon::MessageRef(&*segA, handle));
  sink->close();
  EXPECT_TRUE(a->settle(0).empty()) << "the sender closed its side";
  // The message and the close arrive, but nothing routed the message yet: not over (stopping
  // now would drop it, and a report would miss it).
  EXPECT_EQ(b->settle(0.2), open);
  auto settled = std::async(std::launch::async, [&] { return b->settle(10); });
  Collect received;
  ASSERT_TRUE(receiveUntilClosed(*b, received));
  EXPECT_TRUE(settled.get().empty());
  EXPECT_EQ(received.messages.size(), 1u);
  received.messages.clear();
  auto finishA = std::async(std::launch::async, [&] { a->finish(2); });
  b->finish(2);
  finishA.get();
  a->stop();
  b->stop();
}

TEST(Transport, LargeMessagesArriveIntactAndInOrderUnderCreditFlowControl) {
  LinkedPair pair;  // connection 0 holds 4 messages: the sender must wait for credits
  ASSERT_TRUE(link(pair, std::size_t{256} << 20));
  auto& a = pair.a;
  auto& b = pair.b;
  auto& segA = pair.segA;

  // 12 messages of 6 MiB, each with its own fill byte: far more than the socket buffers hold.
  constexpr int kCount = 12;
  constexpr std::size_t kBytes = 6u << 20;
  auto sink = a->makeSink(0);
  Collect received;
  bool closed = false;
  int sent = 0;
  for (int round = 0; round < 20000 && !closed; ++round) {
    while (sent < kCount && sink->hasSpace()) {
      std::vector<std::byte> fill(kBytes, static_cast<std::byte>(sent + 1));
      msg::VectorSink bytes(kBytes + 1024);
      msg::MessageBuilder builder(bytes);
      builder.setIteration(static_cast<uint64_t>(sent));
      builder.addRawResource(1, true, fill);
      const std::size_t used = builder.finish();
      ASSERT_GT(used, kBytes);
      const uint64_t handle = segA->allocate(used);
      ASSERT_NE(handle, 0u);
      std::memcpy(segA->payload(handle), bytes.buffer().data(), used);
      segA->block(handle).used = used;
      sink->push(daemon::MessageRef(&*segA, handle));
      if (++sent == kCount) sink->close();
    }
    b->receive(0, received, closed);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_TRUE(closed);
  ASSERT_EQ(received.messages.size(), static_cast<std::size_t>(kCount));
  for (int i = 0; i < kCount; ++i) {
    auto view = received.messages[static_cast<std::size_t>(i)].view();
    ASSERT_TRUE(view.ok()) << view.error().message;
    EXPECT_EQ(view->stamps().iteration, static_cast<uint64_t>(i));
    const auto raw = received.messages[static_cast<std::size_t>(i)].bytes();
    // The payload's last byte carries the message's fill.
    EXPECT_EQ(raw[raw.size() - 1], static_cast<std::byte>(i + 1));
  }
  received.messages.clear();
  EXPECT_EQ(b->fatalError(), "");
  auto stopA = std::async(std::launch::async, [&] { a->finish(2); });
  b->finish(2);
  stopA.get();
  a->stop();
  b->stop();
}

TEST(Transport, APeerWithoutTheSecretIsRefused) {
  auto b = Transport::listen(optionsFor(1, newSecret()));
  auto forged = Transport::listen(optionsFor(0, newSecret()));
  ASSERT_TRUE(b.ok() && forged.ok());
  (*b)->addConnection(channel0(false));
  (*forged)->addConnection(channel0(true));
  const std::vector<PeerAddress> peers{{1, "127.0.0.2", (*b)->port()}};
  auto waitB = std::async(std::launch::async, [&] { return (*b)->connectPeers({}); });
  const Status status = (*forged)->connectPeers(peers);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("challenge-response"), std::string::npos) << status.error().message;
  (*forged)->stop();
  (*b)->stop();
  EXPECT_FALSE(waitB.get().ok());  // b never got its authenticated peer
}

TEST(Transport, OversizedMalformedAndUnauthenticatedFramesCloseOnlyThatConnection) {
  auto options = optionsFor(1, newSecret());
  options.connectSeconds = 3;
  auto b = Transport::listen(options);
  ASSERT_TRUE(b.ok());
  (*b)->addConnection(channel0(false));
  auto waitB = std::async(std::launch::async, [&] { return (*b)->connectPeers({}); });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  std::vector<std::vector<std::byte>> attacks;
  {
    std::vector<std::byte> h(kFrameHeaderBytes);  // a message before any handshake
    encodeHeader({FrameType::Message, 0, 64}, h.data());
    attacks.push_back(h);
  }
  {
    std::vector<std::byte> h(kFrameHeaderBytes);  // a hello claiming 4 GiB
    encodeHeader({FrameType::Hello, 0, 0xFFFFFFFFu}, h.data());
    attacks.push_back(h);
  }
  attacks.push_back(std::vector<std::byte>(64, std::byte{0x41}));  // garbage
  for (const auto& bytes : attacks) {
    const int fd = rawConnect((*b)->port());
    ASSERT_EQ(write(fd, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
    EXPECT_TRUE(closedByPeer(fd));
    close(fd);
  }
  EXPECT_EQ((*b)->fatalError(), "");  // the daemon's run is untouched
  EXPECT_FALSE(waitB.get().ok());
  (*b)->stop();
}

}  // namespace
}  // namespace vrflow::net
