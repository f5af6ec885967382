#include "vrflow/net/transport.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sodium.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "handshake.hpp"
#include "vrflow/ipc/block_ref.hpp"
#include "vrflow/ipc/segment.hpp"
#include "vrflow/ipc/sink.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::net {
namespace {

constexpr std::size_t kReadBufferBytes = 256 * 1024;
constexpr std::size_t kDirectReadMin = 16 * 1024;
constexpr int kMaxIov = 64;
constexpr uint64_t kImmediateAfterIdleNs = 20'000;
// accept() out of descriptors (EMFILE/ENFILE): the listening socket is left alone this long,
// doubling up to the maximum, instead of being polled (and failing) in a loop.
constexpr uint64_t kAcceptBackoffMinNs = 50'000'000;
constexpr uint64_t kAcceptBackoffMaxNs = 1'000'000'000;
// Connections refused before authentication: the first few are logged, then one line says
// that the rest are not (a hostile peer must not fill the log).
constexpr int kLoggedRefusals = 5;

uint64_t nowNs() {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::steady_clock::now().time_since_epoch())
                                   .count());
}

std::string errnoText(int err) {
  return std::strerror(err);
}

void put32(std::byte* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out[i] = static_cast<std::byte>((v >> (8 * i)) & 0xFFu);
}
uint32_t get32(const std::byte* in) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(in[i]) << (8 * i);
  return v;
}
void put64(std::byte* out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out[i] = static_cast<std::byte>((v >> (8 * i)) & 0xFFu);
}
uint64_t get64(const std::byte* in) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<uint64_t>(in[i]) << (8 * i);
  return v;
}

std::string peerName(int fd) {
  sockaddr_in addr{};
  socklen_t len = sizeof addr;
  if (getpeername(fd, reinterpret_cast<sockaddr*>(&addr), &len) != 0) return "?";
  char text[INET_ADDRSTRLEN] = "?";
  inet_ntop(AF_INET, &addr.sin_addr, text, sizeof text);
  return std::string(text) + ":" + std::to_string(ntohs(addr.sin_port));
}

void tuneSocket(int fd) {
  int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  int buffer = 4 << 20;
  setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &buffer, sizeof buffer);
  setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof buffer);
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
}

Result<sockaddr_in> resolve(const std::string& address, uint16_t port) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  if (inet_pton(AF_INET, address.c_str(), &addr.sin_addr) != 1) {
    return makeError("'" + address + "' is not an IPv4 address");
  }
  return addr;
}

}  // namespace

namespace {

// One frame waiting to be written: its header (and a control payload), then a message's bytes.
struct OutItem {
  std::array<std::byte, kFrameHeaderBytes + 64> head{};
  std::size_t headBytes = 0;
  ipc::BlockRef message;
  std::size_t total() const { return headBytes + (message.valid() ? message.size() : 0); }
};

struct Link {
  int fd = -1;
  int peer = -1;  ///< -1 until a Hello names it
  bool connector = false;
  bool authenticated = false;
  bool byeReceived = false;
  std::atomic<bool> failed{false};
  std::string address;
  std::array<std::byte, kNonceBytes> nonceC{}, nonceL{};
  std::unique_ptr<FrameReader> reader;
  uint64_t pendingHandle = 0;  ///< a message being received
  std::deque<OutItem> out;     ///< guarded by Impl::mutex
  std::size_t headOffset = 0;  ///< bytes of out.front() already written (I/O thread)
  uint64_t openedNs = 0, lastReceivedNs = 0, lastSentNs = 0;
  LinkStats stats;
};

struct Channel {
  RemoteConnection remote;
  std::deque<ipc::BlockRef> inbox;  ///< incoming: received, not yet routed
  bool closedByPeer = false;
  uint32_t creditsToSend = 0;       ///< incoming: messages routed since the last Credit
  std::atomic<int64_t> credits{0};  ///< outgoing: messages the peer can still take
  bool sentClose = false;
};

}  // namespace

struct Transport::Impl {
  TransportOptions options;
  int listenFd = -1;
  int wakeFd = -1;
  uint16_t boundPort = 0;
  ipc::Segment* segment = nullptr;
  std::map<uint32_t, std::unique_ptr<Channel>> channels;
  std::vector<std::unique_ptr<Link>> links;  ///< I/O thread (and connectPeers before start)
  std::map<int, Link*> linkOfPeer;           ///< guarded by mutex
  std::set<int> neededPeers;
  mutable std::mutex mutex;
  std::condition_variable changed;
  std::string fatal;
  std::string setupFailure;  ///< a link this host opened failed before authentication
  std::thread thread;
  std::atomic<bool> running{false};
  std::atomic<bool> stopped{false};
  std::atomic<bool> wakePending{false};
  std::function<void()> onArrival;
  std::vector<std::byte> readBuffer = std::vector<std::byte>(kReadBufferBytes);
  uint64_t listenPausedUntilNs = 0;  ///< accept() back-off (I/O thread)
  uint64_t acceptBackoffNs = 0;
  bool loggedAcceptFailure = false;
  int loggedRefusals = 0;

  void wake() {
    if (!wakePending.exchange(true)) {
      const uint64_t one = 1;
      [[maybe_unused]] auto n = write(wakeFd, &one, sizeof one);
    }
  }
  std::string hostName(int index) const {
    if (index >= 0 && static_cast<std::size_t>(index) < options.hostNames.size()) {
      return options.hostNames[static_cast<std::size_t>(index)];
    }
    return "#" + std::to_string(index);
  }
  void queueControl(Link& link, FrameType type, uint32_t channel, const std::byte* payload,
                    std::size_t bytes) {
    OutItem item;
    encodeHeader({type, channel, static_cast<uint32_t>(bytes)}, item.head.data());
    if (bytes > 0) std::memcpy(item.head.data() + kFrameHeaderBytes, payload, bytes);
    item.headBytes = kFrameHeaderBytes + bytes;
    link.out.push_back(std::move(item));
  }
  ~Impl() {
    if (wakeFd >= 0) close(wakeFd);
  }
  void newLink(int fd, bool connector, int peer);
  void acceptPeers();
  void releaseRefusedLinks();
  void loop();
  void readFrom(Link& link);
  void writeTo(Link& link);
  int writeLocked(Link& link);
  Status onFrame(Link& link, const FrameHeader& header, std::span<const std::byte> payload);
  void fail(Link& link, const std::string& why);
  void checkTimers();
};

void Transport::Impl::newLink(int fd, bool connector, int peer) {
  auto link = std::make_unique<Link>();
  link->fd = fd;
  link->connector = connector;
  link->peer = connector ? peer : -1;
  link->address = peerName(fd);
  link->openedNs = link->lastReceivedNs = link->lastSentNs = nowNs();
  Link* raw = link.get();
  link->reader = std::make_unique<FrameReader>(
      options.maxFrameBytes,
      [this, raw](const FrameHeader& header) -> std::span<std::byte> {
        if (segment == nullptr) return {};
        const uint64_t handle = segment->allocate(header.length);
        if (handle == 0) return {};
        raw->pendingHandle = handle;
        return {segment->payload(handle), header.length};
      },
      [this, raw](const FrameHeader& header, std::span<const std::byte> payload) {
        return onFrame(*raw, header, payload);
      });
  if (connector) {
    randombytes_buf(link->nonceC.data(), kNonceBytes);
    std::byte hello[16 + kNonceBytes];
    put32(hello, kProtocolVersion);
    put32(hello + 4, static_cast<uint32_t>(options.selfIndex));
    put32(hello + 8, static_cast<uint32_t>(peer));
    put32(hello + 12, 0);
    std::memcpy(hello + 16, link->nonceC.data(), kNonceBytes);
    std::lock_guard lock(mutex);
    queueControl(*link, FrameType::Hello, 0, hello, sizeof hello);
  }
  std::lock_guard lock(mutex);
  links.push_back(std::move(link));
}

Status Transport::Impl::onFrame(Link& link, const FrameHeader& header,
                                std::span<const std::byte> payload) {
  switch (header.type) {
    case FrameType::Hello: {
      if (link.connector || link.peer >= 0) return makeError("unexpected hello");
      const uint32_t version = get32(payload.data());
      const uint32_t from = get32(payload.data() + 4);
      const uint32_t to = get32(payload.data() + 8);
      if (version != kProtocolVersion) {
        return makeError("peer speaks protocol version " + std::to_string(version) + ", not " +
                         std::to_string(kProtocolVersion));
      }
      if (to != static_cast<uint32_t>(options.selfIndex) ||
          from >= static_cast<uint32_t>(options.selfIndex) ||
          neededPeers.count(static_cast<int>(from)) == 0) {
        return makeError("hello names host " + std::to_string(from) + " -> " + std::to_string(to) +
                         ", which is not a link this host expects");
      }
      {
        std::lock_guard lock(mutex);
        if (linkOfPeer.count(static_cast<int>(from)) != 0) {
          return makeError("host '" + hostName(static_cast<int>(from)) + "' is already linked");
        }
      }
      {
        std::lock_guard lock(mutex);  // linkStats() reads it
        link.peer = static_cast<int>(from);
      }
      std::memcpy(link.nonceC.data(), payload.data() + 16, kNonceBytes);
      randombytes_buf(link.nonceL.data(), kNonceBytes);
      const auto mac = detail::proof(options.secret, "vrflow-listener", from, to,
                                     link.nonceC.data(), link.nonceL.data());
      std::byte reply[kNonceBytes + kMacBytes];
      std::memcpy(reply, link.nonceL.data(), kNonceBytes);
      std::memcpy(reply + kNonceBytes, mac.data(), kMacBytes);
      std::lock_guard lock(mutex);
      queueControl(link, FrameType::Challenge, 0, reply, sizeof reply);
      return {};
    }
    case FrameType::Challenge: {
      if (!link.connector) return makeError("unexpected challenge");
      std::memcpy(link.nonceL.data(), payload.data(), kNonceBytes);
      const auto self = static_cast<uint32_t>(options.selfIndex);
      const auto peer = static_cast<uint32_t>(link.peer);
      const auto expected = detail::proof(options.secret, "vrflow-listener", self, peer,
                                          link.nonceC.data(), link.nonceL.data());
      if (!detail::sameMac(expected.data(), payload.data() + kNonceBytes)) {
        return makeError(
            "the peer failed the challenge-response (it does not hold this run's secret)");
      }
      const auto mac = detail::proof(options.secret, "vrflow-connector", self, peer,
                                     link.nonceC.data(), link.nonceL.data());
      std::lock_guard lock(mutex);
      queueControl(link, FrameType::Auth, 0, reinterpret_cast<const std::byte*>(mac.data()),
                   kMacBytes);
      link.authenticated = true;
      link.reader->setAuthenticated(true);
      linkOfPeer[link.peer] = &link;
      changed.notify_all();
      return {};
    }
    case FrameType::Auth: {
      if (link.connector || link.peer < 0) return makeError("unexpected auth");
      const auto expected = detail::proof(
          options.secret, "vrflow-connector", static_cast<uint32_t>(link.peer),
          static_cast<uint32_t>(options.selfIndex), link.nonceC.data(), link.nonceL.data());
      if (!detail::sameMac(expected.data(), payload.data())) {
        return makeError(
            "the peer failed the challenge-response (it does not hold this run's secret)");
      }
      std::lock_guard lock(mutex);
      link.authenticated = true;
      link.reader->setAuthenticated(true);
      linkOfPeer[link.peer] = &link;
      changed.notify_all();
      return {};
    }
    case FrameType::Message: {
      const uint64_t handle = std::exchange(link.pendingHandle, 0);
      ipc::BlockRef message(segment, handle);
      segment->block(handle).used = header.length;
      auto it = channels.find(header.channel);
      if (it == channels.end() || it->second->remote.outgoing ||
          it->second->remote.peer != link.peer) {
        return makeError("message on channel " + std::to_string(header.channel) +
                         ", which is not a connection from host '" + hostName(link.peer) + "'");
      }
      const auto total = msg::MessageView::peekTotalSize(message.bytes());
      if (!total || *total != header.length) {
        return makeError("malformed message on connection " +
                         app::toString(it->second->remote.connection.from) + " -> " +
                         app::toString(it->second->remote.connection.to));
      }
      {
        std::lock_guard lock(mutex);
        if (it->second->closedByPeer) return makeError("message after close on a connection");
        it->second->inbox.push_back(std::move(message));
        ++link.stats.messagesReceived;
        link.stats.bytesReceived += header.length;
      }
      return {};
    }
    case FrameType::Close: {
      auto it = channels.find(header.channel);
      if (it == channels.end() || it->second->remote.outgoing ||
          it->second->remote.peer != link.peer) {
        return makeError("close of channel " + std::to_string(header.channel) +
                         ", not one of this link");
      }
      std::lock_guard lock(mutex);
      it->second->closedByPeer = true;
      changed.notify_all();  // settle() waits on it
      return {};
    }
    case FrameType::Credit: {
      auto it = channels.find(header.channel);
      if (it == channels.end() || !it->second->remote.outgoing ||
          it->second->remote.peer != link.peer) {
        return makeError("credit for channel " + std::to_string(header.channel) +
                         ", not one of this link");
      }
      it->second->credits.fetch_add(get32(payload.data()));
      return {};
    }
    case FrameType::Heartbeat: {
      const auto peerClock = static_cast<int64_t>(get64(payload.data()));
      std::lock_guard lock(mutex);
      link.stats.clockOffsetNs = peerClock - static_cast<int64_t>(nowNs());
      return {};
    }
    case FrameType::Bye: {
      std::lock_guard lock(mutex);  // finish() waits on it
      link.byeReceived = true;
      changed.notify_all();
      return {};
    }
  }
  return makeError("unknown frame");
}

void Transport::Impl::fail(Link& link, const std::string& why) {
  if (link.failed) return;
  link.failed = true;
  if (link.pendingHandle != 0) {
    segment->release(link.pendingHandle);
    link.pendingHandle = 0;
  }
  std::lock_guard lock(mutex);
  if (link.authenticated) {
    if (!link.byeReceived && fatal.empty() && !stopped.load()) {
      fatal = "lost the link to host '" + hostName(link.peer) + "' (" + link.address + "): " + why;
    }
    if (linkOfPeer.count(link.peer) != 0 && linkOfPeer[link.peer] == &link)
      linkOfPeer.erase(link.peer);
  } else if (link.connector && setupFailure.empty()) {
    setupFailure = "host '" + hostName(link.peer) + "' (" + link.address + "): " + why;
  }
  if (link.authenticated || link.connector) {
    if (!link.byeReceived) {
      std::fprintf(stderr, "vrflow-daemon (host %s): closed the connection to host '%s' (%s): %s\n",
                   hostName(options.selfIndex).c_str(), hostName(link.peer).c_str(),
                   link.address.c_str(), why.c_str());
    }
  } else if (loggedRefusals < kLoggedRefusals) {
    ++loggedRefusals;
    std::fprintf(
        stderr, "vrflow-daemon (host %s): closed the connection from %s: %s%s\n",
        hostName(options.selfIndex).c_str(), link.address.c_str(), why.c_str(),
        loggedRefusals == kLoggedRefusals ? " (further refused connections are not logged)" : "");
  }
  link.out.clear();
  if (link.fd >= 0) close(link.fd);
  link.fd = -1;
  changed.notify_all();
}

void Transport::Impl::readFrom(Link& link) {
  for (int round = 0; round < 64 && !link.failed; ++round) {
    auto direct = link.reader->directTarget();
    ssize_t n = 0;
    if (direct.size() >= kDirectReadMin) {
      n = read(link.fd, direct.data(), direct.size());  // straight into shared memory
    } else {
      n = read(link.fd, readBuffer.data(), readBuffer.size());
    }
    if (n < 0) {
      if (errno == EAGAIN || errno == EINTR) return;
      fail(link, "read: " + errnoText(errno));
      return;
    }
    if (n == 0) {
      fail(link, link.byeReceived ? "closed" : "the peer closed the connection");
      return;
    }
    link.lastReceivedNs = nowNs();
    Status status = direct.size() >= kDirectReadMin
                        ? link.reader->advanceDirect(static_cast<std::size_t>(n))
                        : link.reader->feed({readBuffer.data(), static_cast<std::size_t>(n)});
    if (!status) {
      fail(link, status.error().message);
      return;
    }
    if (onArrival) onArrival();
    if (static_cast<std::size_t>(n) <
        (direct.size() >= kDirectReadMin ? direct.size() : readBuffer.size()))
      return;
  }
}

// Writes what the link has queued until the socket is full; the caller holds `mutex`. Returns
// 0, or the errno of a failed write (the caller fails the link, outside the lock).
int Transport::Impl::writeLocked(Link& link) {
  while (!link.failed && link.fd >= 0 && !link.out.empty()) {
    iovec iov[kMaxIov];
    int count = 0;
    std::size_t skip = link.headOffset;
    for (auto& item : link.out) {
      if (count + 2 > kMaxIov) break;
      std::size_t headLeft = item.headBytes;
      const std::byte* head = item.head.data();
      if (skip >= item.headBytes) {
        skip -= item.headBytes;
        headLeft = 0;
      } else {
        head += skip;
        headLeft -= skip;
        skip = 0;
      }
      if (headLeft > 0) iov[count++] = {const_cast<std::byte*>(head), headLeft};
      if (item.message.valid()) {
        auto bytes = item.message.bytes();
        iov[count++] = {const_cast<std::byte*>(bytes.data() + skip), bytes.size() - skip};
        skip = 0;
      }
    }
    const ssize_t n = writev(link.fd, iov, count);
    if (n < 0) {
      if (errno == EAGAIN || errno == EINTR) return 0;
      return errno;
    }
    link.lastSentNs = nowNs();
    std::size_t done = static_cast<std::size_t>(n) + link.headOffset;
    while (!link.out.empty() && done >= link.out.front().total()) {
      done -= link.out.front().total();
      if (link.out.front().message.valid()) {
        ++link.stats.messagesSent;
        link.stats.bytesSent += link.out.front().message.size();
      }
      link.out.pop_front();
    }
    link.headOffset = done;
  }
  return 0;
}

void Transport::Impl::writeTo(Link& link) {
  int err = 0;
  {
    std::lock_guard lock(mutex);
    err = writeLocked(link);
  }
  if (err != 0) fail(link, "write: " + errnoText(err));
}

void Transport::Impl::checkTimers() {
  const uint64_t now = nowNs();
  const auto heartbeatNs = static_cast<uint64_t>(options.heartbeatSeconds * 1e9);
  const auto timeoutNs = static_cast<uint64_t>(options.peerTimeoutSeconds * 1e9);
  const auto handshakeNs = static_cast<uint64_t>(options.handshakeSeconds * 1e9);
  for (auto& link : links) {
    if (link->failed) continue;
    if (!link->authenticated) {
      if (now - link->openedNs > handshakeNs)
        fail(*link, "no authentication within the handshake time");
      continue;
    }
    if (now - link->lastReceivedNs > timeoutNs && !link->byeReceived) {
      char text[96];
      std::snprintf(text, sizeof text, "nothing received for %g s (heartbeat timeout)",
                    options.peerTimeoutSeconds);
      fail(*link, text);
      continue;
    }
    std::lock_guard lock(mutex);
    if (now - link->lastSentNs > heartbeatNs && link->out.empty()) {
      std::byte clock[8];
      put64(clock, now);
      queueControl(*link, FrameType::Heartbeat, 0, clock, sizeof clock);
    }
  }
}

void Transport::Impl::loop() {
  std::vector<pollfd> fds;
  while (running.load()) {
    // Credits for what the routing thread has taken.
    {
      std::lock_guard lock(mutex);
      for (auto& [channel, c] : channels) {
        if (c->remote.outgoing || c->creditsToSend == 0) continue;
        auto it = linkOfPeer.find(c->remote.peer);
        if (it == linkOfPeer.end()) continue;
        std::byte count[4];
        put32(count, c->creditsToSend);
        queueControl(*it->second, FrameType::Credit, channel, count, sizeof count);
        c->creditsToSend = 0;
      }
    }
    fds.clear();
    fds.push_back({wakeFd, POLLIN, 0});
    // The listening socket rests while accept() is backing off.
    fds.push_back({nowNs() >= listenPausedUntilNs ? listenFd : -1, POLLIN, 0});
    for (auto& link : links) {
      short events = 0;
      if (!link->failed) {
        events = POLLIN;
        std::lock_guard lock(mutex);
        if (!link->out.empty()) events |= POLLOUT;
      }
      fds.push_back({link->failed ? -1 : link->fd, events, 0});
    }
    const int timeoutMs = std::max(1, static_cast<int>(options.heartbeatSeconds * 1000 / 2));
    const int ready = poll(fds.data(), fds.size(), timeoutMs);
    if (ready < 0 && errno != EINTR) {
      // Never a silent end: the run learns why its links went quiet.
      const std::string why = "the transport's I/O thread stopped: poll: " + errnoText(errno);
      std::fprintf(stderr, "vrflow-daemon (host %s): %s\n", hostName(options.selfIndex).c_str(),
                   why.c_str());
      std::lock_guard lock(mutex);
      if (fatal.empty()) fatal = why;
      changed.notify_all();
      break;
    }
    if (fds[0].revents & POLLIN) {
      uint64_t value = 0;
      [[maybe_unused]] auto n = read(wakeFd, &value, sizeof value);
      wakePending.store(false);
    }
    if (fds[1].revents & POLLIN) acceptPeers();
    const std::size_t existing = std::min(links.size(), fds.size() - 2);
    for (std::size_t i = 0; i < existing; ++i) {
      Link& link = *links[i];
      const short revents = fds[i + 2].revents;
      if (link.failed) continue;
      if (revents & (POLLIN | POLLHUP | POLLERR)) readFrom(link);
      if (!link.failed) writeTo(link);
    }
    checkTimers();
    for (auto& link : links) {
      if (!link->failed) writeTo(*link);
    }
    releaseRefusedLinks();
  }
}

// Takes what waits on the listening socket. Each accepted connection must authenticate within
// the handshake time; past options.maxUnauthenticatedLinks waiting at once, the oldest waiting
// one is dropped. Out of descriptors, the listening socket rests (back-off) and one line says so.
void Transport::Impl::acceptPeers() {
  for (int round = 0; round < 64; ++round) {
    const int fd = accept4(listenFd, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd < 0) {
      const int err = errno;
      if (err == EMFILE || err == ENFILE || err == ENOBUFS || err == ENOMEM) {
        acceptBackoffNs = acceptBackoffNs == 0 ? kAcceptBackoffMinNs
                                               : std::min(2 * acceptBackoffNs, kAcceptBackoffMaxNs);
        listenPausedUntilNs = nowNs() + acceptBackoffNs;
        if (!loggedAcceptFailure) {
          loggedAcceptFailure = true;
          std::fprintf(stderr,
                       "vrflow-daemon (host %s): cannot accept connections: %s; retrying with "
                       "back-off (raise the open-file limit, `ulimit -n`, if this lasts)\n",
                       hostName(options.selfIndex).c_str(), errnoText(err).c_str());
        }
      }
      return;  // EAGAIN: nothing more waits; others (ECONNABORTED...): the next poll retries
    }
    acceptBackoffNs = 0;
    Link* oldest = nullptr;
    int waiting = 0;
    for (auto& link : links) {
      if (link->failed || link->authenticated || link->connector) continue;
      ++waiting;
      if (oldest == nullptr) oldest = link.get();
    }
    if (waiting >= options.maxUnauthenticatedLinks && oldest != nullptr) {
      fail(*oldest, "dropped: more than " + std::to_string(options.maxUnauthenticatedLinks) +
                        " connections awaiting authentication");
    }
    tuneSocket(fd);
    newLink(fd, false, -1);
  }
}

// A link closed before authentication is released at once (its socket is already closed):
// nothing of it stays in the poll set. Authenticated links stay, failed or not: their counters
// go into the report, and there is at most one per peer.
void Transport::Impl::releaseRefusedLinks() {
  std::lock_guard lock(mutex);  // linkStats() walks the list
  std::erase_if(links, [](const std::unique_ptr<Link>& link) {
    return link->failed && !link->authenticated;
  });
}

Transport::Transport() : impl_(std::make_unique<Impl>()) {}

Transport::~Transport() {
  stop();
}

Result<std::unique_ptr<Transport>> Transport::listen(const TransportOptions& options) {
  if (sodium_init() < 0) return makeError("libsodium failed to initialise");
  std::unique_ptr<Transport> transport(new Transport());
  Impl& t = *transport->impl_;
  t.options = options;
  auto addr = resolve(options.bindAddress, options.port);
  if (!addr) return addr.error();
  t.listenFd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (t.listenFd < 0) return makeError("socket: " + errnoText(errno));
  int one = 1;
  setsockopt(t.listenFd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (bind(t.listenFd, reinterpret_cast<sockaddr*>(&*addr), sizeof *addr) != 0) {
    return makeError("cannot bind " + options.bindAddress + ":" + std::to_string(options.port) +
                     ": " + errnoText(errno));
  }
  if (::listen(t.listenFd, 64) != 0) return makeError("listen: " + errnoText(errno));
  sockaddr_in bound{};
  socklen_t len = sizeof bound;
  getsockname(t.listenFd, reinterpret_cast<sockaddr*>(&bound), &len);
  t.boundPort = ntohs(bound.sin_port);
  fcntl(t.listenFd, F_SETFL, fcntl(t.listenFd, F_GETFL) | O_NONBLOCK);
  t.wakeFd = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (t.wakeFd < 0) return makeError("eventfd: " + errnoText(errno));
  return transport;
}

uint16_t Transport::port() const {
  return impl_->boundPort;
}

void Transport::attachSegment(ipc::Segment& segment) {
  impl_->segment = &segment;
}

void Transport::setArrivalCallback(std::function<void()> callback) {
  impl_->onArrival = std::move(callback);
}

void Transport::addConnection(const RemoteConnection& connection) {
  auto channel = std::make_unique<Channel>();
  channel->remote = connection;
  const std::size_t capacity = connection.connection.capacity > 0
                                   ? static_cast<std::size_t>(connection.connection.capacity)
                                   : 16;
  channel->credits.store(static_cast<int64_t>(capacity));
  impl_->neededPeers.insert(connection.peer);
  impl_->channels[connection.channel] = std::move(channel);
}

namespace {

class RemoteSink final : public ipc::Sink {
 public:
  RemoteSink(Transport::Impl& transport, Channel& channel) : t_(&transport), c_(&channel) {}
  bool hasSpace() const override {
    return c_->remote.connection.policy != app::QueuePolicy::Block || c_->credits.load() > 0;
  }
  void push(ipc::BlockRef message) override {
    if (t_->stopped.load()) return;
    c_->credits.fetch_sub(1);
    {
      std::lock_guard lock(t_->mutex);
      if (t_->stopped.load()) return;  // stop() has dropped what links held
      auto it = t_->linkOfPeer.find(c_->remote.peer);
      if (it == t_->linkOfPeer.end()) return;  // the link is gone: the run is failing already
      OutItem item;
      encodeHeader({FrameType::Message, c_->remote.channel, static_cast<uint32_t>(message.size())},
                   item.head.data());
      item.headBytes = kFrameHeaderBytes;
      item.message = std::move(message);
      Link& link = *it->second;
      link.out.push_back(std::move(item));
      // A link idle for a while is written at once from this (the routing) thread: one thread
      // hop less on the latency path. A stream (messages back to back) is left to the I/O
      // thread, which gathers what accumulates into one writev.
      if (link.out.size() == 1 && nowNs() - link.lastSentNs > kImmediateAfterIdleNs &&
          t_->writeLocked(link) == 0 && link.out.empty()) {
        return;
      }
    }
    t_->wake();
  }
  void close() override {
    if (t_->stopped.load()) return;
    {
      std::lock_guard lock(t_->mutex);
      if (c_->sentClose || t_->stopped.load()) return;
      c_->sentClose = true;
      t_->changed.notify_all();  // settle() waits on it
      auto it = t_->linkOfPeer.find(c_->remote.peer);
      if (it == t_->linkOfPeer.end()) return;
      t_->queueControl(*it->second, FrameType::Close, c_->remote.channel, nullptr, 0);
    }
    t_->wake();
  }

 private:
  Transport::Impl* t_;
  Channel* c_;
};

}  // namespace

std::unique_ptr<ipc::Sink> Transport::makeSink(uint32_t channel) {
  return std::make_unique<RemoteSink>(*impl_, *impl_->channels.at(channel));
}

Status Transport::connectPeers(const std::vector<PeerAddress>& peers) {
  Impl& t = *impl_;
  for (const auto& peer : peers) {
    if (peer.index <= t.options.selfIndex || t.neededPeers.count(peer.index) == 0) continue;
    auto addr = resolve(peer.address, peer.port);
    if (!addr) return addr.error();
    const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return makeError("socket: " + errnoText(errno));
    // Leave from this host's own address, so the peer sees where the link comes from.
    if (auto self = resolve(t.options.bindAddress, 0)) {
      bind(fd, reinterpret_cast<sockaddr*>(&*self), sizeof *self);
    }
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
    int rc = connect(fd, reinterpret_cast<sockaddr*>(&*addr), sizeof *addr);
    if (rc != 0 && errno == EINPROGRESS) {
      pollfd p{fd, POLLOUT, 0};
      rc = poll(&p, 1, static_cast<int>(t.options.connectSeconds * 1000)) == 1 ? 0 : -1;
      int err = ETIMEDOUT;
      if (rc == 0) {
        socklen_t len = sizeof err;
        getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len);
      }
      if (err != 0) {
        close(fd);
        return makeError("cannot reach host '" + t.hostName(peer.index) + "' at " + peer.address +
                         ":" + std::to_string(peer.port) + ": " + errnoText(err));
      }
    } else if (rc != 0) {
      const int err = errno;
      close(fd);
      return makeError("cannot reach host '" + t.hostName(peer.index) + "' at " + peer.address +
                       ":" + std::to_string(peer.port) + ": " + errnoText(err));
    }
    tuneSocket(fd);
    t.newLink(fd, true, peer.index);
  }
  t.running.store(true);
  t.thread = std::thread([&t] { t.loop(); });
  std::unique_lock lock(t.mutex);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(t.options.connectSeconds);
  while (t.fatal.empty()) {
    if (!t.setupFailure.empty()) return makeError(t.setupFailure);
    bool all = true;
    for (const int p : t.neededPeers) all = all && t.linkOfPeer.count(p) != 0;
    if (all) return {};
    if (t.changed.wait_until(lock, deadline) == std::cv_status::timeout) break;
  }
  if (!t.fatal.empty()) return makeError(t.fatal);
  std::string missing;
  for (const int p : t.neededPeers) {
    if (t.linkOfPeer.count(p) == 0)
      missing += (missing.empty() ? "'" : ", '") + t.hostName(p) + "'";
  }
  char text[64];
  std::snprintf(text, sizeof text, "%g s", t.options.connectSeconds);
  return makeError("no authenticated link to host(s) " + missing + " within " + text);
}

std::size_t Transport::receive(uint32_t channel, ipc::Sink& sink, bool& closed) {
  Impl& t = *impl_;
  if (t.stopped.load()) return 0;
  std::size_t moved = 0;
  std::deque<ipc::BlockRef> taken;
  {
    std::lock_guard lock(t.mutex);
    if (t.stopped.load()) return 0;
    Channel& c = *t.channels.at(channel);
    while (!c.inbox.empty() && sink.hasSpace()) {
      sink.push(std::move(c.inbox.front()));
      c.inbox.pop_front();
      ++moved;
    }
    c.creditsToSend += static_cast<uint32_t>(moved);
    closed = c.closedByPeer && c.inbox.empty();
    if (closed) t.changed.notify_all();  // settle() waits on it
  }
  if (moved > 0) t.wake();
  return moved;
}

std::string Transport::fatalError() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->fatal;
}

std::vector<LinkStats> Transport::linkStats() const {
  std::lock_guard lock(impl_->mutex);
  std::vector<LinkStats> stats;
  for (const auto& link : impl_->links) {
    if (link->authenticated) {
      LinkStats s = link->stats;
      s.peer = link->peer;
      stats.push_back(s);
    }
  }
  return stats;
}

std::vector<std::string> Transport::settle(double seconds) {
  Impl& t = *impl_;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  std::unique_lock lock(t.mutex);
  while (true) {
    std::vector<std::string> open;
    for (const auto& [channel, c] : t.channels) {
      const bool over = c->remote.outgoing ? c->sentClose : c->closedByPeer && c->inbox.empty();
      if (!over) {
        open.push_back(app::toString(c->remote.connection.from) + " -> " +
                       app::toString(c->remote.connection.to));
      }
    }
    if (open.empty() || !t.fatal.empty() || t.stopped.load()) return open;
    if (t.changed.wait_until(lock, deadline) == std::cv_status::timeout) return open;
  }
}

void Transport::finish(double seconds) {
  Impl& t = *impl_;
  if (!t.running.load()) return;
  {
    std::lock_guard lock(t.mutex);
    for (auto& [peer, link] : t.linkOfPeer) t.queueControl(*link, FrameType::Bye, 0, nullptr, 0);
  }
  t.wake();
  std::unique_lock lock(t.mutex);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (true) {
    bool done = true;
    for (auto& [peer, link] : t.linkOfPeer) done = done && link->byeReceived && link->out.empty();
    if (done) break;
    if (t.changed.wait_until(lock, deadline) == std::cv_status::timeout) break;
  }
}

void Transport::stop() {
  Impl& t = *impl_;
  t.stopped.store(true);
  if (t.running.exchange(false)) {
    t.wake();
    t.thread.join();
  }
  // Under the lock: a routing thread that has just seen `stopped` false (in a sink's push or
  // close, or in receive()) holds it while it touches a link or an inbox, and looks again once
  // it has it.
  std::lock_guard lock(t.mutex);
  for (auto& link : t.links) {
    if (link->pendingHandle != 0 && t.segment != nullptr) t.segment->release(link->pendingHandle);
    link->pendingHandle = 0;
    link->out.clear();
    if (link->fd >= 0) close(link->fd);
    link->fd = -1;
  }
  for (auto& [channel, c] : t.channels) c->inbox.clear();
  if (t.listenFd >= 0) close(t.listenFd);
  t.listenFd = -1;
  // The eventfd stays open until the Transport goes (~Impl): a routing thread may still ring it.
}

}  // namespace vrflow::net
