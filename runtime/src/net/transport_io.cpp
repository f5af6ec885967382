#include <poll.h>
#include <sys/uio.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <utility>

#include "transport_impl.hpp"

// The transport's I/O thread: one poll loop over the listening socket and every link, reading
// frames (straight into shared memory when large), writing what is queued with writev,
// sending credits and heartbeats, and timing out silent links.
namespace vrflow::net {

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
    // Routed once a frame that moves something is complete (not per chunk of a large one).
    if (std::exchange(routable, false) && onArrival) onArrival();
    // A short read into the buffer drained the socket. A large payload read straight into
    // shared memory goes on while the sender keeps it coming (until EAGAIN), without a poll
    // (and a wake-up) per chunk.
    if (direct.size() < kDirectReadMin && static_cast<std::size_t>(n) < readBuffer.size()) return;
  }
}

// Writes what the link has queued until the socket is full, or `budget` bytes are written; the
// caller holds `mutex`. Returns 0, or the errno of a failed write (the caller fails the link,
// outside the lock). One writev takes at most kMaxWriteBytes: the kernel sends a large write's
// segments (paced) only when the call lets go of the socket, so the peer starts reading after
// the first chunk instead of after the whole socket buffer.
int Transport::Impl::writeLocked(Link& link, std::size_t budget) {
  while (!link.failed && link.fd >= 0 && !link.out.empty() && budget > 0) {
    iovec iov[kMaxIov];
    int count = 0;
    std::size_t room = std::min(kMaxWriteBytes, budget);
    std::size_t skip = link.headOffset;
    for (auto& item : link.out) {
      if (count + 2 > kMaxIov || room == 0) break;
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
      if (headLeft > 0) {
        const std::size_t take = std::min(headLeft, room);
        iov[count++] = {const_cast<std::byte*>(head), take};
        room -= take;
        if (take < headLeft) break;
      }
      if (item.message.valid() && room > 0) {
        auto bytes = item.message.bytes();
        const std::size_t take = std::min(bytes.size() - skip, room);
        iov[count++] = {const_cast<std::byte*>(bytes.data() + skip), take};
        room -= take;
        skip = 0;
      }
    }
    const ssize_t n = writev(link.fd, iov, count);
    if (n < 0) {
      if (errno == EAGAIN || errno == EINTR) return 0;
      return errno;
    }
    link.lastSentNs = nowNs();
    ++link.stats.writeCalls;
    budget -= std::min(budget, static_cast<std::size_t>(n));
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

void Transport::Impl::queueCredits(Link& link, bool all) {
  std::erase_if(link.owed, [&](Channel* c) {
    if (c->creditsToSend == 0) return true;
    if (!all && c->creditsToSend < creditBatch(c->remote) && link.out.empty()) return false;
    std::byte count[4];
    put32(count, c->creditsToSend);
    queueControl(link, FrameType::Credit, c->remote.channel, count, sizeof count);
    ++link.stats.creditFramesSent;
    c->creditsToSend = 0;
    return true;
  });
}

void Transport::Impl::loop() {
  ioThreadOf = this;
  std::vector<pollfd> fds;
  while (running.load()) {
    // Credits for what was routed into the connections' queues: in batches, or along with
    // frames that leave anyway (a reply, a heartbeat), never a segment of their own per message.
    {
      std::lock_guard lock(mutex);
      for (auto& [peer, link] : linkOfPeer) queueCredits(*link, false);
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

}  // namespace vrflow::net
