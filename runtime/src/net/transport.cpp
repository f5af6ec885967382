#include "vrflow/net/transport.hpp"

#include <sodium.h>
#include <sys/eventfd.h>

#include <cerrno>
#include <cstdio>

#include "transport_impl.hpp"
#include "vrflow/ipc/sink.hpp"

// The transport's public calls, its channels (one per connection crossing hosts) and their
// credit-based flow control.
namespace vrflow::net {

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
  channel->credits.store(static_cast<int64_t>(channelCapacity(connection)));
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
      Link& link = *it->second;
      const bool idle = link.out.empty();
      // Credits owed to the peer leave with this message, in the same writev: a request-reply
      // exchange never sends a credit frame of its own (nor wakes the peer's I/O thread for it).
      t_->queueCredits(link, true);
      OutItem item;
      encodeHeader({FrameType::Message, c_->remote.channel, static_cast<uint32_t>(message.size())},
                   item.head.data());
      item.headBytes = kFrameHeaderBytes;
      item.message = std::move(message);
      link.out.push_back(std::move(item));
      // A link idle for a while is written at once from this (the routing) thread: one thread
      // hop less on the latency path. A stream (messages back to back) is left to the I/O
      // thread, which gathers what accumulates into one writev, and so is what a large message
      // has left after its first kImmediateWriteBytes (not written under the routing lock).
      if (idle && nowNs() - link.lastSentNs > kImmediateAfterIdleNs &&
          t_->writeLocked(link, kImmediateWriteBytes) == 0 && link.out.empty()) {
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

std::size_t Transport::receive(uint32_t channel, ipc::Sink& sink, bool& closed) {
  Impl& t = *impl_;
  if (t.stopped.load()) return 0;
  std::size_t moved = 0;
  bool creditsDue = false;
  {
    std::lock_guard lock(t.mutex);
    if (t.stopped.load()) return 0;
    Channel& c = *t.channels.at(channel);
    while (!c.inbox.empty() && sink.hasSpace()) {
      sink.push(std::move(c.inbox.front()));
      c.inbox.pop_front();
      ++moved;
    }
    if (moved > 0 && c.creditsToSend == 0) {
      auto it = t.linkOfPeer.find(c.remote.peer);
      if (it != t.linkOfPeer.end()) it->second->owed.push_back(&c);
    }
    c.creditsToSend += static_cast<uint32_t>(moved);
    creditsDue = moved > 0 && c.creditsToSend >= creditBatch(c.remote);
    closed = c.closedByPeer && c.inbox.empty();
    if (closed) t.changed.notify_all();  // settle() waits on it
  }
  if (creditsDue) t.wake();  // the I/O thread sends them (on that thread: its next round)
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
  std::thread loop;
  {
    std::lock_guard lock(t.mutex);  // against connectPeers() starting the loop meanwhile
    t.stopped.store(true);
    if (t.running.exchange(false)) loop = std::move(t.thread);
  }
  if (loop.joinable()) {
    t.wake();
    loop.join();
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
