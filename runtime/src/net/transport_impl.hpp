#pragma once

// Internal to the transport: the state behind Transport, shared by the files that implement it
// (transport.cpp: the public calls, channels and credits; transport_links.cpp: opening links,
// the handshake and the frames a link receives; transport_io.cpp: the I/O thread's loop).

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "vrflow/ipc/block_ref.hpp"
#include "vrflow/ipc/segment.hpp"
#include "vrflow/net/frame.hpp"
#include "vrflow/net/transport.hpp"

namespace vrflow::net {

// Small frames are read in batches through this buffer; a large message's payload goes straight
// into its block, except what the read that brought its header also took (copied, at most this).
inline constexpr std::size_t kReadBufferBytes = 64 * 1024;
inline constexpr std::size_t kDirectReadMin = 16 * 1024;
inline constexpr int kMaxIov = 64;
// Bytes per writev call (see writeLocked), and what the routing path writes at once on an idle
// link before it leaves the rest of a large message to the I/O thread (it holds the routing
// lock meanwhile).
inline constexpr std::size_t kMaxWriteBytes = 256 * 1024;
inline constexpr std::size_t kImmediateWriteBytes = 1024 * 1024;
inline constexpr uint64_t kImmediateAfterIdleNs = 20'000;
// accept() out of descriptors (EMFILE/ENFILE): the listening socket is left alone this long,
// doubling up to the maximum, instead of being polled (and failing) in a loop.
inline constexpr uint64_t kAcceptBackoffMinNs = 50'000'000;
inline constexpr uint64_t kAcceptBackoffMaxNs = 1'000'000'000;
// Connections refused before authentication: the first few are logged, then one line says
// that the rest are not (a hostile peer must not fill the log).
inline constexpr int kLoggedRefusals = 5;

inline uint64_t nowNs() {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::steady_clock::now().time_since_epoch())
                                   .count());
}

inline std::string errnoText(int err) {
  return std::strerror(err);
}

inline void put32(std::byte* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out[i] = static_cast<std::byte>((v >> (8 * i)) & 0xFFu);
}
inline uint32_t get32(const std::byte* in) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(in[i]) << (8 * i);
  return v;
}
inline void put64(std::byte* out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out[i] = static_cast<std::byte>((v >> (8 * i)) & 0xFFu);
}
inline uint64_t get64(const std::byte* in) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<uint64_t>(in[i]) << (8 * i);
  return v;
}

inline std::string peerName(int fd) {
  sockaddr_in addr{};
  socklen_t len = sizeof addr;
  if (getpeername(fd, reinterpret_cast<sockaddr*>(&addr), &len) != 0) return "?";
  char text[INET_ADDRSTRLEN] = "?";
  inet_ntop(AF_INET, &addr.sin_addr, text, sizeof text);
  return std::string(text) + ":" + std::to_string(ntohs(addr.sin_port));
}

// TCP_NODELAY and non-blocking. Both socket buffers are left to the kernel's autotuning, as for
// a plain socket (raw TCP): the receive buffer grows up to net.ipv4.tcp_rmem's maximum (32 MiB on
// the project's machine). A fixed SO_RCVBUF turns autotuning off and is capped at
// net.core.rmem_max (4 MiB, doubled); a fixed 4 MiB SO_SNDBUF (doubled) let one writev copy
// 8 MiB or more before the peer could read it (see writeLocked).
inline void tuneSocket(int fd) {
  int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
}

inline Result<sockaddr_in> resolve(const std::string& address, uint16_t port) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  if (inet_pton(AF_INET, address.c_str(), &addr.sin_addr) != 1) {
    return makeError("'" + address + "' is not an IPv4 address");
  }
  return addr;
}

// One frame waiting to be written: its header (and a control payload), then a message's bytes.
struct OutItem {
  std::array<std::byte, kFrameHeaderBytes + 64> head{};
  std::size_t headBytes = 0;
  ipc::BlockRef message;
  std::size_t total() const { return headBytes + (message.valid() ? message.size() : 0); }
};

struct Channel;

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
  std::vector<Channel*> owed;  ///< incoming channels of this peer owing credits; guarded by mutex
  uint64_t openedNs = 0, lastReceivedNs = 0, lastSentNs = 0;
  LinkStats stats;
};

// A connection's queue capacity, as its sender's credits start.
inline std::size_t channelCapacity(const RemoteConnection& remote) {
  return remote.connection.capacity > 0 ? static_cast<std::size_t>(remote.connection.capacity) : 16;
}

// Credits go back once this many are owed (or with other frames of the link): never a frame per
// message, and the sender, holding the other half, never waits for them.
inline uint32_t creditBatch(const RemoteConnection& remote) {
  return static_cast<uint32_t>(std::max<std::size_t>(1, channelCapacity(remote) / 2));
}

struct Channel {
  RemoteConnection remote;
  std::deque<ipc::BlockRef> inbox;  ///< incoming: received, not yet routed
  bool closedByPeer = false;
  uint32_t creditsToSend = 0;       ///< incoming: messages routed since the last Credit
  std::atomic<int64_t> credits{0};  ///< outgoing: messages the peer can still take
  bool sentClose = false;
};

// The transport whose I/O thread this is (nullptr on any other thread): what the I/O thread
// queues while it routes is written by its own loop, so it never rings itself.
inline thread_local const Transport::Impl* ioThreadOf = nullptr;

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
  /// A message, close or credit frame was read since the last onArrival (I/O thread).
  bool routable = false;
  std::vector<std::byte> readBuffer = std::vector<std::byte>(kReadBufferBytes);
  uint64_t listenPausedUntilNs = 0;  ///< accept() back-off (I/O thread)
  uint64_t acceptBackoffNs = 0;
  bool loggedAcceptFailure = false;
  int loggedRefusals = 0;

  bool onIoThread() const { return ioThreadOf == this; }
  void wake() {
    if (onIoThread()) return;  // the loop looks at every link before it polls again
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
  // Queues the credits that the link's incoming channels owe: all of them when `all` (a frame
  // leaves now anyway, they ride in its system call), else those owing a batch, or all when
  // the link has other frames waiting. The caller holds `mutex`.
  void queueCredits(Link& link, bool all);
  ~Impl() {
    if (wakeFd >= 0) close(wakeFd);
  }
  void newLink(int fd, bool connector, int peer);
  void acceptPeers();
  void releaseRefusedLinks();
  void loop();
  void readFrom(Link& link);
  void writeTo(Link& link);
  int writeLocked(Link& link, std::size_t budget = SIZE_MAX);
  Status onFrame(Link& link, const FrameHeader& header, std::span<const std::byte> payload);
  void fail(Link& link, const std::string& why);
  void checkTimers();
};

}  // namespace vrflow::net
