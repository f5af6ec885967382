#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
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
  void failing(const run::RunOutcome& outcome) override;
  void report(const std::string& json) override;
  void trace(const std::string& json) override;
  void stats(const std::string& json) override;
  /// Sends a line of this host's event stream to the launcher, which merges every host's.
  void event(const std::string& line);
  /// Sends a line a module printed to the launcher, within kOutputLinesPerSecond and
  /// kOutputBytesPerSecond (with bursts of twice that); the lines over it are counted, and the
  /// count is sent ("dropped MODULE N") before the next line sent, or at the end.
  void output(const std::string& module, std::string_view text) override;
  static constexpr double kOutputLinesPerSecond = 2000;
  static constexpr double kOutputBytesPerSecond = 2 * 1024 * 1024;

 private:
  ControlLink(int in, int out) : in_(in), out_(out) { inbox_->out = out; }
  void send(const net::ControlEvent& event);
  /// The next command from the launcher (End when it went away, and from then on); waits up to
  /// `seconds` (negative: forever); none on timeout.
  std::optional<net::ControlCommand> next(double seconds);
  /// After "quit": waits until the connections crossing hosts are over (or a stop comes);
  /// returns a warning for those still open.
  std::vector<std::string> settle();

  /// The counts of lines not forwarded, as "dropped" events (and reset).
  std::vector<net::ControlEvent> takeDropped();
  /// The rate limit of output(): its budgets, refilled with time, and what it dropped.
  struct OutputBudget {
    std::mutex mutex;
    double lines = 2 * kOutputLinesPerSecond;
    double bytes = 2 * kOutputBytesPerSecond;
    std::chrono::steady_clock::time_point refilled = std::chrono::steady_clock::now();
    std::map<std::string, uint64_t> dropped;
  } budget_;

  /// Stops before "go" ("stop" or the end of input): says so on stderr; the error.
  Status stoppedBeforeStart(const net::ControlCommand& command);

  int in_, out_;
  std::string host_;
  int selfIndex_ = 0;
  bool stopped_ = false;       ///< the launcher said stop (or went away)
  bool finishedSent_ = false;  ///< failing() said this host's end before drain()
  std::unique_ptr<net::Transport> transport_;
  std::vector<net::RemoteConnection> remote_;
  std::vector<uint32_t> localChannels_;
  /// The launcher's commands, shared with the thread that reads them: it blocks in read() until
  /// the launcher closes the channel, which may come after this object is gone.
  struct Inbox {
    std::mutex mutex;
    std::condition_variable changed;
    std::deque<net::ControlCommand> commands;  ///< parsed; malformed lines are dropped
    int out = -1;                              ///< the channel to the launcher
    std::mutex writeMutex;                     ///< one line at a time on `out`, from either thread
  };
  /// Writes `event` as one line on the channel to the launcher (any thread).
  static void sendOn(Inbox& inbox, const net::ControlEvent& event);
  std::shared_ptr<Inbox> inbox_ = std::make_shared<Inbox>();
  /// Reads and parses the launcher's lines until the end of input (`host` names the daemon in
  /// the warning for a malformed line).
  static void readLoop(int fd, const std::string& host, const std::shared_ptr<Inbox>& inbox);
};

}  // namespace vrflow::tools
