// TCP transports of the benchmark, on loopback, on the same plan as the others:
//   raw-tcp     a plain socket pair between this process and a forked child (TCP_NODELAY):
//               the floor any TCP transport pays (two kernel copies, no framing, no routing).
//   vrflow-tcp  module -> daemon (host a, 127.0.0.1) -> TCP -> daemon (host b, 127.0.0.2) ->
//               module, started with `vrflow launch --backend local`: the whole path a
//               message takes between two hosts, default filters included.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "child_process.hpp"
#include "transport_bench.hpp"

namespace vrflow::bench {
namespace {

namespace fs = std::filesystem;

std::int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

bool readAll(int fd, unsigned char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t r = read(fd, p, n);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    p += r;
    n -= static_cast<std::size_t>(r);
  }
  return true;
}

bool writeAll(int fd, const unsigned char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t r = write(fd, p, n);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    p += r;
    n -= static_cast<std::size_t>(r);
  }
  return true;
}

void noDelay(int fd) {
  int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
}

// A listening socket on 127.0.0.1 and its port.
Result<std::pair<int, uint16_t>> listenLoopback() {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd < 0 || bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      listen(fd, 1) != 0) {
    return makeError(std::string("raw-tcp: cannot listen on loopback: ") + std::strerror(errno));
  }
  socklen_t len = sizeof addr;
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  return std::make_pair(fd, ntohs(addr.sin_port));
}

int connectLoopback(uint16_t port) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(port);
  if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) return -1;
  noDelay(fd);
  return fd;
}

// One size of raw-tcp: ping-pong round trips, then a one-way stream.
Result<BenchResult> rawTcpSize(std::size_t bytes, const BenchSettings& settings) {
  const IterationPlan plan = iterationPlan(bytes, settings.quick);
  std::vector<unsigned char> payload = makePayload(bytes);
  auto listening = listenLoopback();
  if (!listening) return listening.error();
  const auto [listenFd, port] = *listening;
  const std::size_t rounds = plan.warmupMessages + plan.pingPongs;
  const std::size_t total = plan.warmupMessages + plan.streamMessages;
  auto peer = ChildProcess::fork([&, port = port] {
    const int fd = connectLoopback(port);
    if (fd < 0) return 3;
    std::vector<unsigned char> buffer(bytes);
    for (std::size_t i = 0; i < rounds; ++i) {
      if (!readAll(fd, buffer.data(), bytes) || !writeAll(fd, buffer.data(), bytes)) return 4;
    }
    for (std::size_t i = 0; i < total; ++i) {
      if (!writeAll(fd, payload.data(), bytes)) return 5;
    }
    unsigned char done = 0;
    return readAll(fd, &done, 1) ? 0 : 6;
  });
  if (!peer) {
    close(listenFd);
    return peer.error();
  }
  const int fd = accept4(listenFd, nullptr, nullptr, SOCK_CLOEXEC);
  close(listenFd);
  if (fd < 0) return makeError("raw-tcp: accept failed");
  noDelay(fd);
  std::vector<unsigned char> buffer(bytes);
  std::vector<std::int64_t> samples;
  for (std::size_t i = 0; i < rounds; ++i) {
    const std::int64_t start = nowNs();
    if (!writeAll(fd, payload.data(), bytes) || !readAll(fd, buffer.data(), bytes)) {
      close(fd);
      return makeError("raw-tcp: the peer went away during ping-pong");
    }
    if (i >= plan.warmupMessages) samples.push_back(nowNs() - start);
  }
  std::int64_t start = nowNs();
  for (std::size_t i = 0; i < total; ++i) {
    if (!readAll(fd, buffer.data(), bytes)) {
      close(fd);
      return makeError("raw-tcp: the peer went away during streaming");
    }
    if (i + 1 == plan.warmupMessages) start = nowNs();
  }
  const std::int64_t end = nowNs();
  if (std::memcmp(buffer.data(), payload.data(), bytes) != 0) {
    close(fd);
    return makeError("raw-tcp: a streamed message differs from the one sent");
  }
  const unsigned char done = 1;
  writeAll(fd, &done, 1);
  auto status = peer->wait(settings.peerTimeout);
  close(fd);
  if (!status) return status.error();
  if (*status != 0) return makeError("raw-tcp: peer " + ChildProcess::describeExit(*status));
  const double rate =
      static_cast<double>(plan.streamMessages) / (static_cast<double>(end - start) * 1e-9);
  return makeResult("raw-tcp", bytes, samples, rate,
                    "plain TCP socket pair on 127.0.0.1, TCP_NODELAY, blocking read/write, "
                    "2 processes (fork); receiver reads into one reused buffer");
}

std::string selfFolder() {
  std::error_code ec;
  return fs::read_symlink("/proc/self/exe", ec).parent_path().string();
}

// The bench package's manifest, for the daemons started by `vrflow launch`.
void writeManifest(const fs::path& dir) {
  fs::create_directories(dir / "bench");
  std::ofstream out(dir / "bench" / "vrflow-package.xml");
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<package name=\"bench\" version=\"1\">\n"
      << "  <module type=\"peer\" executable=\"" << selfFolder()
      << "/vrflow-bench-peer\" kind=\"other\">\n"
      << "    <doc>Transport benchmark peer.</doc>\n"
      << "    <input name=\"in\" data=\"any\"/>\n    <output name=\"out\" data=\"any\"/>\n";
  out << "    <param name=\"role\" type=\"string\" default=\"pong\" doc=\"-\"/>\n"
      << "    <param name=\"size\" type=\"int\" default=\"64\" min=\"0\" doc=\"-\"/>\n"
      << "    <param name=\"warmup\" type=\"int\" default=\"0\" min=\"0\" doc=\"-\"/>\n"
      << "    <param name=\"results\" type=\"file\" default=\"\" doc=\"-\"/>\n"
      << "    <param name=\"count\" type=\"int\" default=\"0\" min=\"0\" doc=\"-\"/>\n";
  out << "  </module>\n</package>\n";
}

std::string twoHosts(const std::string& name, const std::string& modules,
                     const std::string& connections) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"" + name +
         "\" version=\"1\">\n  <hosts>\n    <host id=\"a\" address=\"127.0.0.1\"/>\n"
         "    <host id=\"b\" address=\"127.0.0.2\"/>\n  </hosts>\n  <modules>\n" +
         modules + "  </modules>\n  <connections>\n" + connections +
         "  </connections>\n</application>\n";
}

Status launch(const fs::path& app, const fs::path& packages, const BenchSettings& settings) {
  auto child = ChildProcess::spawn({selfFolder() + "/vrflow", "--packages", packages.string(),
                                    "launch", app.string(), "--backend", "local"});
  if (!child) return child.error();
  auto status = child->wait(settings.peerTimeout);
  if (!status) return status.error();
  if (*status != 0)
    return makeError("vrflow-tcp: vrflow launch " + ChildProcess::describeExit(*status));
  return {};
}

}  // namespace

Result<std::vector<BenchResult>> runRawTcp(const BenchSettings& settings) {
  return forEachSize(settings, [&](std::size_t bytes) { return rawTcpSize(bytes, settings); });
}

Result<std::vector<BenchResult>> runVrflowTcp(const BenchSettings& settings) {
  char pattern[] = "/tmp/vrflow-bench-tcp-XXXXXX";
  if (mkdtemp(pattern) == nullptr) return makeError("vrflow-tcp: cannot make a temporary folder");
  const fs::path dir(pattern);
  writeManifest(dir / "packages");
  return runEachSize(settings, dir, [&](std::size_t bytes) -> Result<BenchResult> {
    const IterationPlan plan = iterationPlan(bytes, settings.quick);
    const std::string size = std::to_string(bytes), warmup = std::to_string(plan.warmupMessages);
    const fs::path rtt = dir / ("rtt-" + size), rate = dir / ("rate-" + size);
    const std::string pingCount = std::to_string(plan.warmupMessages + plan.pingPongs + 1);
    std::ofstream(dir / "pingpong.xml") << twoHosts(
        "bench-tcp-ping-pong",
        "    <module id=\"ping\" package=\"bench\" type=\"peer\" host=\"a\">\n"
        "      <param name=\"role\" value=\"ping\"/>\n      <param name=\"size\" value=\"" +
            size +
            "\"/>\n"
            "      <param name=\"warmup\" value=\"" +
            warmup +
            "\"/>\n"
            "      <param name=\"results\" value=\"" +
            rtt.string() +
            "\"/>\n"
            "      <param name=\"count\" value=\"" +
            pingCount +
            "\"/>\n"
            "      <input port=\"in\" initial-messages=\"1\"/>\n    </module>\n"
            "    <module id=\"pong\" package=\"bench\" type=\"peer\" host=\"b\">\n"
            "      <param name=\"role\" value=\"pong\"/>\n    </module>\n",
        "    <connection from=\"ping.out\" to=\"pong.in\"/>\n"
        "    <connection from=\"pong.out\" to=\"ping.in\"/>\n");
    if (Status ran = launch(dir / "pingpong.xml", dir / "packages", settings); !ran) {
      return ran.error();
    }
    std::ofstream(dir / "stream.xml") << twoHosts(
        "bench-tcp-stream",
        "    <module id=\"send\" package=\"bench\" type=\"peer\" host=\"a\">\n"
        "      <param name=\"role\" value=\"send\"/>\n      <param name=\"size\" value=\"" +
            size +
            "\"/>\n"
            "      <param name=\"count\" value=\"" +
            std::to_string(plan.warmupMessages + plan.streamMessages) +
            "\"/>\n    </module>\n"
            "    <module id=\"recv\" package=\"bench\" type=\"peer\" host=\"b\">\n"
            "      <param name=\"role\" value=\"recv\"/>\n      <param name=\"warmup\" value=\"" +
            warmup +
            "\"/>\n"
            "      <param name=\"results\" value=\"" +
            rate.string() + "\"/>\n    </module>\n",
        "    <connection from=\"send.out\" to=\"recv.in\" capacity=\"" +
            std::to_string(streamQueueDepth(bytes)) + "\"/>\n");
    if (Status ran = launch(dir / "stream.xml", dir / "packages", settings); !ran) {
      return ran.error();
    }
    return readPeerResult(
        "vrflow-tcp", bytes, rtt.string(), rate.string(),
        "module -> daemon (127.0.0.1) -> TCP -> daemon (127.0.0.2) -> module via vrflow launch "
        "--backend local; writev from and read into shared memory, credit flow control");
  });
}

}  // namespace vrflow::bench
