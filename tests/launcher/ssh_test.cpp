// The ssh backend against a real sshd that this test starts on loopback, with keys it makes.
#include <arpa/inet.h>
#include <dirent.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "cluster_helpers.hpp"
#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

// A private sshd on 127.0.0.1-3 at a free port, accepting one generated key.
bool hasChildren(pid_t parent) {
  DIR* dir = opendir("/proc");
  bool any = false;
  while (dirent* e = readdir(dir)) {
    const int pid = std::atoi(e->d_name);
    if (pid <= 0) continue;
    std::ifstream in("/proc/" + std::string(e->d_name) + "/stat");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto close = text.rfind(')');
    if (close == std::string::npos) continue;
    char state = 0;
    int ppid = 0;
    if (std::sscanf(text.c_str() + close + 1, " %c %d", &state, &ppid) == 2 && ppid == parent)
      any = true;
  }
  closedir(dir);
  return any;
}

class Sshd {
 public:
  explicit Sshd(const TempDir& dir) : dir_(dir) {}
  ~Sshd() { stop(); }
  // Empty on success, else why sshd cannot run here.
  std::string start() {
    if (access("/usr/sbin/sshd", X_OK) != 0) return "/usr/sbin/sshd is not installed";
    // sshd insists on its privilege-separation folder; as root we may make it (it is what the
    // openssh-server service would do), otherwise sshd cannot run as this user.
    if (access("/run/sshd", F_OK) != 0) {
      if (geteuid() != 0) return "/run/sshd is missing and only root may create it";
      mkdir("/run/sshd", 0755);
    }
    for (const char* key : {"host_key", "user_key"}) {
      const auto made = runCommand(
          {"/usr/bin/ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-f", dir_.file(key)}, 30);
      if (made.exitCode != 0) return "ssh-keygen failed: " + made.err;
    }
    dir_.write("authorized_keys", readFile(dir_.file("user_key.pub")));
    chmod(dir_.file("authorized_keys").c_str(), 0600);
    // A port below the kernel's ephemeral range (32768 and up here), free on all three
    // addresses: a port in that range may be taken on 127.0.0.1 alone by some client's
    // connection, and sshd then listens on .2 and .3 only.
    std::string why;
    for (int attempt = 0; attempt < 8; ++attempt) {
      port_ = freeOnEveryAddress(20000 + static_cast<int>((getpid() * 7 + attempt * 997) % 12000));
      if (port_ == 0) continue;
      why = launch();
      if (why.empty()) return {};
    }
    return why;
  }
  void stop() {
    if (pid_ > 0) {
      // Let sshd's per-session processes finish their tear-down first (they end once the
      // session's processes, our daemons, have ended); what outlives this shows up as leftover.
      for (int i = 0; i < 50 && hasChildren(pid_); ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
      kill(pid_, SIGTERM);
      int status = 0;
      waitpid(pid_, &status, 0);
      pid_ = -1;
    }
  }
  std::string hostLine(const std::string& host, const std::string& address) const {
    return host + " address=" + address + " ssh-port=" + std::to_string(port_) +
           " identity=" + dir_.file("user_key") +
           " ssh-option=StrictHostKeyChecking=no ssh-option=UserKnownHostsFile=/dev/null"
           " ssh-option=LogLevel=ERROR\n";
  }

 private:
  // `port` when nothing is bound to it on 127.0.0.1-3, else 0.
  static int freeOnEveryAddress(int port) {
    for (const char* address : {"127.0.0.1", "127.0.0.2", "127.0.0.3"}) {
      const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
      sockaddr_in addr{};
      addr.sin_family = AF_INET;
      addr.sin_port = htons(static_cast<uint16_t>(port));
      inet_pton(AF_INET, address, &addr.sin_addr);
      const bool free = fd >= 0 && bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
      if (fd >= 0) close(fd);
      if (!free) return 0;
    }
    return port;
  }
  // Starts sshd on port_; empty once a login works through every one of its addresses.
  std::string launch() {
    dir_.write("sshd_config", "Port " + std::to_string(port_) +
                                  "\nListenAddress 127.0.0.1\nListenAddress 127.0.0.2\n"
                                  "ListenAddress 127.0.0.3\nHostKey " +
                                  dir_.file("host_key") + "\nAuthorizedKeysFile " +
                                  dir_.file("authorized_keys") + "\nPidFile " +
                                  dir_.file("sshd.pid") +
                                  "\nUsePAM no\nStrictModes no\nPasswordAuthentication no\n"
                                  "KbdInteractiveAuthentication no\nPubkeyAuthentication yes\n"
                                  "PermitRootLogin prohibit-password\nLogLevel ERROR\n");
    pid_ = fork();
    if (pid_ == 0) {
      execl("/usr/sbin/sshd", "/usr/sbin/sshd", "-D", "-f", dir_.file("sshd_config").c_str(), "-E",
            dir_.file("sshd.log").c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    const auto login = [&](const char* address) {
      return runCommand(
                 {"/usr/bin/ssh", "-T", "-o", "BatchMode=yes", "-o", "StrictHostKeyChecking=no",
                  "-o", "UserKnownHostsFile=/dev/null", "-o", "LogLevel=ERROR", "-i",
                  dir_.file("user_key"), "-p", std::to_string(port_), address, "true"},
                 20)
                 .exitCode == 0;
    };
    // Ready when a login works through each address the hostfile will name.
    for (int i = 0; i < 50; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      if (login("127.0.0.1") && login("127.0.0.2") && login("127.0.0.3")) return {};
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return "sshd did not start: " + readFile(dir_.file("sshd.log"));
      }
    }
    const std::string why = "no login through sshd on port " + std::to_string(port_) +
                            " within 5 s: " + readFile(dir_.file("sshd.log"));
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return why;
  }

  const TempDir& dir_;
  pid_t pid_ = -1;
  int port_ = 0;
};

TEST(LaunchSsh, ThreeHostsThroughSshdGiveTheSameDigestsAsOneHost) {
  TempDir dir;
  Sshd sshd(dir);
  if (const std::string why = sshd.start(); !why.empty()) GTEST_SKIP() << why;
  const auto hosts =
      dir.write("hosts", sshd.hostLine("a", "127.0.0.1") + sshd.hostLine("b", "127.0.0.2") +
                             sshd.hostLine("c", "127.0.0.3"));
  const std::string app = sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml";
  const auto three = runVrflow({"launch", app, "--backend", "ssh", "--hosts", hosts, "-n", "100",
                                "--report", dir.file("three.json")},
                               120);
  const auto one = runVrflow({"run", sourceDir() + "/examples/pipeline/pipeline.xml", "-n", "100",
                              "--no-progress", "--report", dir.file("one.json")},
                             120);
  sshd.stop();
  ASSERT_EQ(three.exitCode, 0) << three.err;
  ASSERT_EQ(one.exitCode, 0) << one.err;
  EXPECT_EQ(deterministicPart(dir.file("one.json")), deterministicPart(dir.file("three.json")));
  const auto left = leftoverProcesses();
  EXPECT_TRUE(left.empty()) << ::testing::PrintToString(left);
}

TEST(LaunchSsh, AnUnreachableHostIsNamed) {
  TempDir dir;
  // Nothing listens on port 1: ssh fails, and the launcher names the host's daemon.
  const auto hosts = dir.write("hosts",
                               "a address=127.0.0.1 ssh-port=1\nb address=127.0.0.2 ssh-port=1\n"
                               "c address=127.0.0.3 ssh-port=1\n");
  const auto result =
      runVrflow({"launch", sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml",
                 "--backend", "ssh", "--hosts", hosts, "-n", "5"},
                60);
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("daemon of host '"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("ssh pid"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("exited with status 255"), std::string::npos) << result.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

}  // namespace
}  // namespace vrflow::testing
