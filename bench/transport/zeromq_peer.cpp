// ZeroMQ peer: libzmq over ipc:// (a Unix domain socket) between two processes, close to the way
// ZeroMQ's own perf tools measure it: REQ/REP ping-pong as local_lat/remote_lat; streaming as
// local_thr/remote_thr, but over PAIR so the receiver can tell the sender it is done (PAIR and
// PUSH/PULL move data alike between two peers).
//
// Copies, as an expert would set it up: the sender wraps the payload, allocated and filled once,
// with zmq_msg_init_data(..., ffn = nullptr). libzmq then makes a *constant* message: no
// allocation, no copy; for messages at least as large as its 8 KiB batch its encoder hands the
// payload straight to write(). The receiver takes each message as a zmq_msg (zmq_msg_recv) and
// reads it in place, never copying it out. What remains is what ZeroMQ really costs: the kernel's
// two copies through the socket, one malloc per received message over 33 bytes (libzmq reads a
// large body straight into it), and the hand-off between each process's I/O thread and its
// application thread.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>
#include <zmq.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "child_process.hpp"
#include "transport_bench.hpp"

namespace vrflow::bench {

namespace {

using Clock = std::chrono::steady_clock;
const char* kTransport = "zeromq-ipc";  // or zeromq-tcp, set by the entry point
// Blocking calls wake up this often to check that the peer process is still alive.
constexpr int kLivenessSliceMs = 200;
constexpr int kReconnectMs = 10;

std::int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

Error zmqError(const std::string& what) {
  return makeError(what + ": " + zmq_strerror(zmq_errno()));
}

constexpr const char* kSocketDirPrefix = "vrflow-bench-zmq-";

// Removes socket directories left by runs that were killed (SIGKILL leaves no chance to clean
// up): their names carry the pid of the run that made them.
void removeStaleSocketDirs() {
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator("/tmp", error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kSocketDirPrefix, 0) != 0) {
      continue;
    }
    const long owner = std::strtol(name.c_str() + std::strlen(kSocketDirPrefix), nullptr, 10);
    if (owner > 0 && kill(static_cast<pid_t>(owner), 0) != 0 && errno == ESRCH) {
      std::filesystem::remove_all(entry.path(), error);
    }
  }
}

/// A private directory for the ipc:// socket files, removed with everything in it.
class SocketDir {
 public:
  static Result<SocketDir> create() {
    removeStaleSocketDirs();
    std::string pattern =
        std::string("/tmp/") + kSocketDirPrefix + std::to_string(getpid()) + "-XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) {
      return makeError("cannot create a directory for the ipc sockets under /tmp");
    }
    return SocketDir(std::move(pattern));
  }
  SocketDir(SocketDir&& other) noexcept : path_(std::exchange(other.path_, {})) {}
  SocketDir& operator=(SocketDir&&) = delete;
  SocketDir(const SocketDir&) = delete;
  SocketDir& operator=(const SocketDir&) = delete;
  ~SocketDir() {
    if (!path_.empty()) {
      std::error_code ignored;
      std::filesystem::remove_all(path_, ignored);
    }
  }

  /// The ipc:// address of a socket file in this directory.
  std::string address(const char* name) const { return "ipc://" + path_ + "/" + name; }

 private:
  explicit SocketDir(std::string path) : path_(std::move(path)) {}
  std::string path_;
};

/// A ZeroMQ context; created after fork in each process, never shared across one.
class Context {
 public:
  Context() : context_(zmq_ctx_new()) {}
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  ~Context() {
    if (context_ != nullptr) {
      zmq_ctx_term(context_);
    }
  }
  void* get() const { return context_; }

 private:
  void* context_;
};

/// A ZeroMQ socket with its options; closed before its context is terminated.
class Socket {
 public:
  Socket(const Context& context, int type)
      : socket_(context.get() != nullptr ? zmq_socket(context.get(), type) : nullptr) {}
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
  ~Socket() {
    if (socket_ != nullptr) {
      zmq_close(socket_);
    }
  }
  void* get() const { return socket_; }

  /// Sets integer options, then binds (parent) or connects (child) to address.
  Status open(std::initializer_list<std::pair<int, int>> options, const std::string& address,
              bool bind) const {
    if (socket_ == nullptr) {
      return zmqError("zmq_socket");
    }
    for (const auto& [option, value] : options) {
      if (zmq_setsockopt(socket_, option, &value, sizeof value) != 0) {
        return zmqError("zmq_setsockopt " + std::to_string(option));
      }
    }
    const int rc =
        bind ? zmq_bind(socket_, address.c_str()) : zmq_connect(socket_, address.c_str());
    if (rc != 0) {
      return zmqError((bind ? "zmq_bind " : "zmq_connect ") + address);
    }
    return {};
  }

 private:
  void* socket_;
};

int toMs(std::chrono::milliseconds timeout) {
  return static_cast<int>(timeout.count());
}

// Repeats a ZeroMQ call that returns -1/EAGAIN on its short timeout until it succeeds, the peer
// process has ended (it may only end once we said we are done), or nothing moved for `timeout`.
template <typename Call>
Status untilDone(const Call& call, ChildProcess& peer, std::chrono::milliseconds timeout,
                 const char* what) {
  const auto deadline = Clock::now() + timeout;
  while (call() < 0) {
    if (zmq_errno() != EAGAIN && zmq_errno() != EINTR) {
      return zmqError(what);
    }
    if (!peer.running()) {
      return makeError(std::string(what) + ": the peer process ended early (" +
                       peer.exitDescription() + ")");
    }
    if (Clock::now() > deadline) {
      return makeError(std::string(what) + ": no progress for " +
                       std::to_string(timeout.count() / 1000) + " s");
    }
  }
  return {};
}

// The peer's last step in both phases: wait for our empty "done" message, then exit. libzmq may
// drop messages still queued when a socket closes, LINGER or not (libzmq issues #1922, #4660),
// so neither side closes while the other may still be reading.
int awaitDone(void* socket) {
  zmq_msg_t done;
  zmq_msg_init(&done);
  const int received = zmq_msg_recv(&done, socket, 0);
  zmq_msg_close(&done);
  return received == 0 ? 0 : 4;
}

// Our side of that: say "done", and keep the socket open until the peer has exited.
Status finishPeer(void* socket, ChildProcess& peer, std::chrono::milliseconds timeout) {
  Status sent =
      untilDone([socket] { return zmq_send(socket, nullptr, 0, 0); }, peer, timeout, "send done");
  if (!sent) {
    return sent;
  }
  auto status = peer.wait(timeout);
  if (!status) {
    return makeError("peer " + status.error().message);
  }
  if (*status != 0) {
    return makeError("peer " + ChildProcess::describeExit(*status));
  }
  return {};
}

// Child of the latency phase: echoes every request back, as ZeroMQ's local_lat does.
int echoPeer(const std::string& address, std::size_t rounds, std::chrono::milliseconds timeout) {
  const Context context;
  const Socket rep(context, ZMQ_REP);
  const Status opened = rep.open({{ZMQ_RCVTIMEO, toMs(timeout)},
                                  {ZMQ_SNDTIMEO, toMs(timeout)},
                                  {ZMQ_LINGER, 0},
                                  {ZMQ_RECONNECT_IVL, kReconnectMs}},
                                 address, /*bind=*/false);
  if (!opened) {
    return 2;
  }
  zmq_msg_t message;
  zmq_msg_init(&message);
  int code = 0;
  for (std::size_t i = 0; i < rounds && code == 0; ++i) {
    // Sending the received message back moves it: no copy.
    if (zmq_msg_recv(&message, rep.get(), 0) < 0 || zmq_msg_send(&message, rep.get(), 0) < 0) {
      code = 3;
    }
  }
  zmq_msg_close(&message);
  return code == 0 ? awaitDone(rep.get()) : code;
}

// Child of the streaming phase: sends `count` constant messages as fast as the high-water mark
// allows. PAIR rather than PUSH, so the same socket carries our "done" back.
int streamPeer(const std::string& address, std::vector<unsigned char>& payload, std::size_t count,
               int highWaterMark, std::chrono::milliseconds timeout) {
  const Context context;
  const Socket pair(context, ZMQ_PAIR);
  const Status opened = pair.open({{ZMQ_SNDHWM, highWaterMark},
                                   {ZMQ_SNDTIMEO, toMs(timeout)},
                                   {ZMQ_RCVTIMEO, toMs(timeout)},
                                   {ZMQ_LINGER, 0},
                                   {ZMQ_RECONNECT_IVL, kReconnectMs}},
                                  address, /*bind=*/false);
  if (!opened) {
    return 2;
  }
  for (std::size_t i = 0; i < count; ++i) {
    zmq_msg_t message;
    zmq_msg_init_data(&message, payload.data(), payload.size(), nullptr, nullptr);
    if (zmq_msg_send(&message, pair.get(), 0) < 0) {
      zmq_msg_close(&message);
      return 3;
    }
  }
  return awaitDone(pair.get());
}

bool matchesPayload(zmq_msg_t& message, const std::vector<unsigned char>& payload) {
  const auto* data = static_cast<const unsigned char*>(zmq_msg_data(&message));
  return zmq_msg_size(&message) == payload.size() && data[0] == payload.front() &&
         data[payload.size() - 1] == payload.back();
}

// Round-trip samples (ns) of REQ/REP ping-pong with a forked echo peer.
Result<std::vector<std::int64_t>> measureRoundTrips(std::vector<unsigned char>& payload,
                                                    const IterationPlan& plan,
                                                    const std::string& address,
                                                    std::chrono::milliseconds timeout) {
  const std::size_t rounds = plan.warmupMessages + plan.pingPongs;
  auto peer = ChildProcess::fork([&] { return echoPeer(address, rounds, timeout); });
  if (!peer) {
    return peer.error();
  }
  const Context context;
  const Socket req(context, ZMQ_REQ);
  const Status opened = req.open(
      {{ZMQ_RCVTIMEO, kLivenessSliceMs}, {ZMQ_SNDTIMEO, kLivenessSliceMs}, {ZMQ_LINGER, 0}},
      address, /*bind=*/true);
  if (!opened) {
    return opened.error();
  }
  std::vector<std::int64_t> samples;
  samples.reserve(plan.pingPongs);
  zmq_msg_t reply;
  zmq_msg_init(&reply);
  Status done;
  for (std::size_t i = 0; i < rounds && done; ++i) {
    zmq_msg_t request;
    zmq_msg_init_data(&request, payload.data(), payload.size(), nullptr, nullptr);
    const std::int64_t start = nowNs();
    done = untilDone([&] { return zmq_msg_send(&request, req.get(), 0); }, *peer, timeout,
                     "send request");
    if (done) {
      done = untilDone([&] { return zmq_msg_recv(&reply, req.get(), 0); }, *peer, timeout,
                       "receive reply");
    }
    const std::int64_t end = nowNs();
    if (done && !matchesPayload(reply, payload)) {
      done = makeError("the echoed message differs from the one sent");
    }
    if (done && i >= plan.warmupMessages) {
      samples.push_back(end - start);
    }
    zmq_msg_close(&request);  // a no-op once sent; releases it when the send failed
  }
  if (done && std::memcmp(zmq_msg_data(&reply), payload.data(), payload.size()) != 0) {
    done = makeError("the last echoed message differs from the one sent");
  }
  zmq_msg_close(&reply);
  if (done) {
    done = finishPeer(req.get(), *peer, timeout);
  }
  if (!done) {
    return done.error();
  }
  return samples;
}

// Messages per second received from a forked peer that streams without pause.
Result<double> measureStream(std::vector<unsigned char>& payload, const IterationPlan& plan,
                             const std::string& address, std::chrono::milliseconds timeout) {
  const std::size_t total = plan.warmupMessages + plan.streamMessages;
  const int highWaterMark = static_cast<int>(streamQueueDepth(payload.size()));
  auto peer = ChildProcess::fork(
      [&] { return streamPeer(address, payload, total, highWaterMark, timeout); });
  if (!peer) {
    return peer.error();
  }
  const Context context;
  const Socket pair(context, ZMQ_PAIR);
  const Status opened = pair.open({{ZMQ_RCVHWM, highWaterMark},
                                   {ZMQ_RCVTIMEO, kLivenessSliceMs},
                                   {ZMQ_SNDTIMEO, kLivenessSliceMs},
                                   {ZMQ_LINGER, 0}},
                                  address, /*bind=*/true);
  if (!opened) {
    return opened.error();
  }
  zmq_msg_t message;
  zmq_msg_init(&message);
  Status done;
  std::int64_t start = 0;
  for (std::size_t i = 0; i < total && done; ++i) {
    done = untilDone([&] { return zmq_msg_recv(&message, pair.get(), 0); }, *peer, timeout,
                     "receive streamed message");
    if (done && !matchesPayload(message, payload)) {
      done = makeError("a streamed message differs from the one sent");
    }
    // The clock starts once the warm-up messages are in: steady state only.
    if (i + 1 == plan.warmupMessages) {
      start = nowNs();
    }
  }
  const std::int64_t end = nowNs();
  zmq_msg_close(&message);
  if (done) {
    done = finishPeer(pair.get(), *peer, timeout);
  }
  if (!done) {
    return done.error();
  }
  return static_cast<double>(plan.streamMessages) / (static_cast<double>(end - start) * 1e-9);
}

std::string describeSetup(std::size_t bytes) {
  int major = 0;
  int minor = 0;
  int patch = 0;
  zmq_version(&major, &minor, &patch);
  return "libzmq " + std::to_string(major) + "." + std::to_string(minor) + "." +
         std::to_string(patch) +
         ", 2 processes (fork), 1 I/O thread each; REQ/REP ping-pong, PAIR stream with HWM " +
         std::to_string(streamQueueDepth(bytes)) +
         "; zero-copy send (zmq_msg_init_data, constant message), receive into zmq_msg_t";
}

// A free port on 127.0.0.1 for a tcp:// endpoint (found by binding port 0, then released).
std::string freeTcpAddress() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  socklen_t len = sizeof addr;
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  close(fd);
  return "tcp://127.0.0.1:" + std::to_string(ntohs(addr.sin_port));
}

Result<std::vector<BenchResult>> runZeromqOn(const BenchSettings& settings, bool tcp) {
  kTransport = tcp ? "zeromq-tcp" : "zeromq-ipc";
  if (const int threads = threadCount(); threads != 1) {
    return makeError(std::string(kTransport) + ": runZeromq forks its peer and must be called " +
                     "while the process has one thread (it has " + std::to_string(threads) + ")");
  }
  auto dir = SocketDir::create();
  if (!dir) {
    return makeError(std::string(kTransport) + ": " + dir.error().message);
  }
  std::vector<BenchResult> results;
  for (const std::size_t bytes : settings.sizes) {
    const std::string where = std::string(kTransport) + ", " + std::to_string(bytes) + " B: ";
    std::vector<unsigned char> payload = makePayload(bytes);
    const IterationPlan plan = iterationPlan(bytes, settings.quick);
    auto roundTrips = measureRoundTrips(
        payload, plan, tcp ? freeTcpAddress() : dir->address("pingpong"), settings.peerTimeout);
    if (!roundTrips) {
      return makeError(where + roundTrips.error().message);
    }
    auto rate = measureStream(payload, plan, tcp ? freeTcpAddress() : dir->address("stream"),
                              settings.peerTimeout);
    if (!rate) {
      return makeError(where + rate.error().message);
    }
    results.push_back(
        makeResult(kTransport, bytes, *roundTrips, *rate,
                   (tcp ? "tcp://127.0.0.1 (TCP_NODELAY), " : "") + describeSetup(bytes)));
  }
  return results;
}

}  // namespace

Result<std::vector<BenchResult>> runZeromq(const BenchSettings& settings) {
  return runZeromqOn(settings, false);
}

Result<std::vector<BenchResult>> runZeromqTcp(const BenchSettings& settings) {
  return runZeromqOn(settings, true);
}

}  // namespace vrflow::bench
