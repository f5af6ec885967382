#pragma once

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/net/control.hpp"
#include "vrflow/net/transport.hpp"
#include "vrflow/run/runner.hpp"

namespace vrflow::tools {

/// vrflow-daemon under `vrflow launch`: the launcher's line protocol on two descriptors
/// (docs/transport.md, "Launcher and daemons") and the TCP transport to the other hosts.
class ControlLink final : public run::HostLink {
 public:
  /// Reads the run secret (first line of `in`), binds the transport and tells the launcher its
  /// port. `bindAddress` empty: the host's address in the file.
  /// `secret`: already known (mpirun: from the environment), else read from `in`.
  static Result<std::unique_ptr<ControlLink>> create(const app::Application& application,
                                                     const std::string& host,
                                                     const std::string& bindAddress,
                                                     double peerTimeoutSeconds, int in, int out,
                                                     std::optional<net::Secret> secret = {});
  /// mpirun: the daemon connects back to the launcher at `address` (HOST:PORT), proves it holds
  /// the run secret, and returns the socket (the control channel both ways).
  static Result<int> connectBack(const std::string& address, const net::Secret& secret,
                                 int hostIndex);
  ~ControlLink() override;

  void configure(daemon::DaemonOptions& options) override;
  Status ready() override;
  std::optional<run::RunOutcome> poll() override;
  std::vector<std::string> drain(const run::RunOutcome& outcome) override;
  void report(const std::string& json) override;
  void trace(const std::string& json) override;
  void stats(const std::string& json) override;

 private:
  ControlLink(int in, int out) : in_(in), out_(out) { inbox_->out = out; }
  void send(const std::string& line);
  /// The next command from the launcher ("eof" when it went away); waits up to `seconds`
  /// (negative: forever); empty on timeout.
  std::string next(double seconds);
  /// After "quit": waits until the connections crossing hosts are over (or a stop comes);
  /// returns a warning for those still open.
  std::vector<std::string> settle();

  /// The next command from the launcher, waiting for it; none (and a line on stderr) for a
  /// malformed one.
  std::optional<net::ControlCommand> nextCommand();
  /// Stops before "go" ("stop" or the end of input): says so on stderr; the error.
  Status stoppedBeforeStart(const net::ControlCommand& command);

  int in_, out_;
  std::string host_;
  int selfIndex_ = 0;
  bool stopped_ = false;  ///< the launcher said stop (or went away)
  uint32_t hostId_ = 0;
  std::unique_ptr<net::Transport> transport_;
  std::vector<net::RemoteConnection> remote_;
  std::vector<uint32_t> localChannels_;
  /// The launcher's lines, shared with the thread that reads them: it blocks in read() until
  /// the launcher closes the channel, which may come after this object is gone.
  struct Inbox {
    std::mutex mutex;
    std::condition_variable changed;
    std::deque<std::string> lines;
    int out = -1;           ///< the channel to the launcher
    std::mutex writeMutex;  ///< one line at a time on `out`, from either thread
  };
  /// Writes `line` and a newline on the channel to the launcher (any thread).
  static void sendOn(Inbox& inbox, const std::string& line);
  std::shared_ptr<Inbox> inbox_ = std::make_shared<Inbox>();
  static void readLoop(int fd, const std::shared_ptr<Inbox>& inbox);
};

}  // namespace vrflow::tools
