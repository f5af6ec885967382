#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/ipc/segment.hpp"
#include "vrflow/ipc/sink.hpp"
#include "vrflow/net/frame.hpp"

// TCP between host daemons: one authenticated, persistent link per pair of hosts that share a
// connection; messages of every connection between the two hosts travel on it as frames.
namespace vrflow::net {

/// The per-run secret the launcher hands to every daemon (never on a command line).
using Secret = std::array<uint8_t, 32>;
/// A fresh random secret (libsodium's randombytes).
Secret newSecret();
/// Lower-case hex, 64 characters.
std::string secretToHex(const Secret& secret);
/// Parses secretToHex()'s form; an error for anything else.
Result<Secret> secretFromHex(const std::string& text);

/// What a daemon started through mpirun proves to the launcher when it connects back:
/// hex HMAC-SHA256(secret, "vrflow-control\0" | u32 host index | nonce text).
std::string controlProof(const Secret& secret, int hostIndex, const std::string& nonce);
/// A fresh random nonce, as 64 hex digits.
std::string newNonceHex();

/// Where another host's daemon listens.
struct PeerAddress {
  int index = -1;  ///< the host's position in the application file
  std::string address;
  uint16_t port = 0;
};

/// A connection of the application that crosses this host's boundary.
struct RemoteConnection {
  uint32_t channel = 0;  ///< the connection's index in the (expanded) application file
  app::Connection connection;
  int peer = -1;          ///< index of the other host
  bool outgoing = false;  ///< true when this host holds the source
};

/// Settings of one daemon's transport.
struct TransportOptions {
  int selfIndex = 0;                   ///< this host's index in the application file
  std::vector<std::string> hostNames;  ///< host ids by index, for messages
  std::string bindAddress = "127.0.0.1";
  uint16_t port = 0;  ///< 0: any free port (reported by port())
  Secret secret{};
  uint32_t maxFrameBytes = kDefaultMaxFrameBytes;
  double heartbeatSeconds = 0.2;    ///< a link silent this long gets a heartbeat
  double peerTimeoutSeconds = 3.0;  ///< a link silent this long is declared lost
  double handshakeSeconds = 5.0;    ///< an unauthenticated link is dropped after this
  /// At most this many accepted connections wait for authentication at once; one more drops
  /// the oldest of them (docs/transport.md, "Unauthenticated connections").
  int maxUnauthenticatedLinks = 16;
  double connectSeconds = 10.0;  ///< connectPeers() gives up after this
};

/// Counters of one link, for monitoring.
struct LinkStats {
  int peer = -1;
  uint64_t messagesSent = 0, bytesSent = 0, messagesReceived = 0, bytesReceived = 0;
  /// Credit frames queued, and writev calls made: a credit owed when a message leaves rides in
  /// that message's call (docs/transport.md, "Data path").
  uint64_t creditFramesSent = 0, writeCalls = 0;
  int64_t clockOffsetNs = 0;  ///< peer's steady clock minus ours, from heartbeats (approximate)
};

/// One daemon's end of the network: a listening socket, its links to peers and an I/O thread.
class Transport {
 public:
  /// Binds and listens on options.bindAddress:options.port, and starts the I/O thread.
  static Result<std::unique_ptr<Transport>> listen(const TransportOptions& options);
  ~Transport();
  Transport(const Transport&) = delete;
  Transport& operator=(const Transport&) = delete;

  /// The port actually bound.
  uint16_t port() const;
  /// Where received messages are written; set before any peer may send.
  void attachSegment(ipc::Segment& segment);
  /// Declares a connection crossing hosts (both directions), before connectPeers().
  void addConnection(const RemoteConnection& connection);
  /// A sink that sends an outgoing connection's messages to its peer (flow-controlled by
  /// credits for the block policy). The Transport must outlive it or be stopped first.
  std::unique_ptr<ipc::Sink> makeSink(uint32_t channel);
  /// Connects to the peers of higher index and waits until every peer that shares a
  /// connection with this host is linked and authenticated (both directions).
  Status connectPeers(const std::vector<PeerAddress>& peers);
  /// Moves messages received on an incoming connection into `sink` while it has space; sets
  /// `closed` once the peer closed the connection and nothing is left. Returns messages moved.
  std::size_t receive(uint32_t channel, ipc::Sink& sink, bool& closed);
  /// The first failure of an established link (peer lost, malformed frame), or empty.
  std::string fatalError() const;
  /// Waits up to `seconds` until every connection crossing this host's boundary is over: each
  /// outgoing one closed here (after its last message), each incoming one closed by its peer
  /// with every message it sent taken by receive(). Returns early on a link failure
  /// (fatalError()). Returns the connections not over yet ("FROM -> TO"), none when all are.
  std::vector<std::string> settle(double seconds);
  /// Flushes what is queued, says goodbye to every peer, and waits up to `seconds` for theirs.
  void finish(double seconds);
  /// Stops the I/O thread, closes every socket and drops every held message.
  void stop();
  /// Per-link counters (thread-safe snapshot).
  std::vector<LinkStats> linkStats() const;
  /// Called from the routing thread's wake-ups: the daemon's doorbell to ring on arrivals.
  void setArrivalCallback(std::function<void()> callback);

  struct Impl;

 private:
  Transport();
  std::unique_ptr<Impl> impl_;
};

}  // namespace vrflow::net
