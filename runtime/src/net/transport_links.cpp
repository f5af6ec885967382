#include <poll.h>
#include <sodium.h>

#include <cerrno>
#include <cstdio>

#include "handshake.hpp"
#include "transport_impl.hpp"
#include "vrflow/message/reader.hpp"

// A transport's links: opening them (connecting to peers, accepting them), the handshake that
// authenticates them, the frames they receive, and their failure.
namespace vrflow::net {

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
        routable = true;
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
      routable = true;
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
      routable = true;  // a sink that had no room may take what waits for it
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
  {
    // Under the lock that stop() takes: a stop() from another thread either comes first (no
    // loop starts) or finds the loop's thread to join (it never joins one not yet assigned, nor
    // leaves one running that the destructor would then destroy joinable).
    std::lock_guard startLock(t.mutex);
    if (t.stopped.load()) return makeError("the transport was stopped before its peers connected");
    t.running.store(true);
    t.thread = std::thread([&t] { t.loop(); });
  }
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

}  // namespace vrflow::net
