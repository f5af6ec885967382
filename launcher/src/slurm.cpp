// The slurm backend: inside an allocation (salloc, sbatch), one `srun` step per host runs its
// daemon on a node of the allocation; the control channel is srun's stdin and stdout, as with a
// local daemon, so the run secret goes on stdin and a dead daemon or node ends its srun.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <sstream>

#include "launcher.hpp"
#include "vrflow/run/process.hpp"

namespace vrflow::launcher::detail {
namespace {

// What a short command (scontrol, squeue) prints on stdout, or an error naming it; killed
// after 20 s.
Result<std::string> commandOutput(const std::vector<std::string>& argv) {
  int out[2];
  if (pipe2(out, O_CLOEXEC) != 0) return makeError(std::string("pipe: ") + std::strerror(errno));
  run::ProcessSettings settings;
  settings.argv = argv;
  settings.environment = run::environmentWith({});
  settings.stdoutFd = out[1];
  auto pid = run::spawnProcess(settings);
  close(out[1]);
  if (!pid) {
    close(out[0]);
    return pid.error();
  }
  std::string text;
  const auto until = Clock::now() + std::chrono::seconds(20);
  for (char buffer[4096]; Clock::now() < until;) {
    pollfd p{out[0], POLLIN, 0};
    if (poll(&p, 1, 100) != 1) continue;
    const ssize_t n = read(out[0], buffer, sizeof buffer);
    if (n <= 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
  }
  close(out[0]);
  if (Clock::now() >= until) kill(-*pid, SIGKILL);
  int status = 0;
  waitpid(*pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string command;
    for (const auto& word : argv) command += (command.empty() ? "" : " ") + word;
    return makeError("`" + command + "` failed (" +
                     (WIFEXITED(status) ? "exit " + std::to_string(WEXITSTATUS(status))
                                        : std::string("killed")) +
                     ")");
  }
  return text;
}

// The value of `key=` in one line of `scontrol show node -o`.
std::string fieldOf(const std::string& line, const std::string& key) {
  std::istringstream words(line);
  for (std::string word; words >> word;) {
    if (word.rfind(key + "=", 0) == 0) return word.substr(key.size() + 1);
  }
  return {};
}

}  // namespace

Result<std::string> ipv4Of(const std::string& name) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  addrinfo* found = nullptr;
  if (const int err = getaddrinfo(name.c_str(), nullptr, &hints, &found); err != 0) {
    return makeError("cannot resolve '" + name + "' to an IPv4 address: " + gai_strerror(err));
  }
  char text[INET_ADDRSTRLEN] = {};
  inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(found->ai_addr)->sin_addr, text, sizeof text);
  freeaddrinfo(found);
  return std::string(text);
}

Status insideSlurmAllocation() {
  for (const char* name : {"SLURM_JOB_ID", "SLURM_JOB_NODELIST"}) {
    if (std::getenv(name) == nullptr) {
      return makeError(std::string("--backend slurm runs inside a Slurm allocation (salloc or "
                                   "sbatch): ") +
                       name + " is not set");
    }
  }
  return {};
}

Result<SlurmAllocation> slurmAllocation() {
  if (auto inside = insideSlurmAllocation(); !inside) return inside.error();
  const char* job = std::getenv("SLURM_JOB_ID");
  const char* list = std::getenv("SLURM_JOB_NODELIST");
  SlurmAllocation allocation;
  allocation.jobId = job;
  auto names = commandOutput({"scontrol", "show", "hostnames", list});
  if (!names) return makeError("slurm job " + allocation.jobId + ": " + names.error().message);
  std::istringstream lines(*names);
  for (std::string node; lines >> node;) allocation.nodes.push_back(node);
  if (allocation.nodes.empty()) {
    return makeError("slurm job " + allocation.jobId + ": no node in '" + list + "'");
  }
  auto shown = commandOutput({"scontrol", "show", "node", "-o", list});
  if (!shown) return makeError("slurm job " + allocation.jobId + ": " + shown.error().message);
  for (const auto& node : allocation.nodes) {
    std::istringstream nodeLines(*shown);
    std::string address = node;  // a node without NodeAddr is reached by its name
    for (std::string line; std::getline(nodeLines, line);) {
      if (fieldOf(line, "NodeName") == node && !fieldOf(line, "NodeAddr").empty()) {
        address = fieldOf(line, "NodeAddr");
      }
    }
    auto ip = ipv4Of(address);
    if (!ip) return makeError("slurm node '" + node + "': " + ip.error().message);
    allocation.addresses.push_back(*ip);
  }
  return allocation;
}

// Host i on node i of the allocation, wrapping around when there are more hosts than nodes
// (several daemons on one node, each on its own port); a hostfile's node= or Open MPI line
// chooses the node instead, and its address= the address.
Result<Placement> Launcher::slurmPlacement(const SlurmAllocation& allocation, std::size_t index,
                                           const HostEntry* entry) const {
  Placement placement;
  placement.entry = entry;
  std::size_t node = index % allocation.nodes.size();
  if (entry != nullptr && !entry->node.empty()) {
    node = allocation.nodes.size();
    for (std::size_t n = 0; n < allocation.nodes.size(); ++n) {
      if (allocation.nodes[n] == entry->node) node = n;
    }
    if (node == allocation.nodes.size()) {
      return makeError(options_.hostfile + ":" + std::to_string(entry->line) + ": error: node '" +
                       entry->node + "' of host '" + entry->host + "' is not in slurm job " +
                       allocation.jobId + " (" + std::getenv("SLURM_JOB_NODELIST") + ")");
    }
  }
  placement.node = allocation.nodes[node];
  placement.bind = allocation.addresses[node];
  if (entry != nullptr) {
    if (!entry->address.empty()) placement.bind = entry->address;
    placement.environment = entry->environment;
  }
  return placement;
}

// One step per host (not one srun for all): each daemon keeps its own control channel on its
// srun's stdin and stdout, so the secret never leaves a pipe, and the end of one srun names
// its host.
std::vector<std::string> Launcher::srunCommand(const std::string& node,
                                               const std::string& host) const {
  return {"srun",
          "--nodes=1",
          "--ntasks=1",
          "--nodelist=" + node,
          "--overlap",     // steps share the allocation's CPUs: several daemons may share a node
          "--export=ALL",  // the search paths and the hostfile's env=, whatever the site's default
          "--kill-on-bad-exit=1",
          "--quiet",
          "--job-name=vrflow-" + std::to_string(getpid()) + "-" + host};
}

void Launcher::cancelSlurmSteps() const {
  const char* job = std::getenv("SLURM_JOB_ID");
  if (options_.backend != "slurm" || job == nullptr) return;
  const std::string prefix = "vrflow-" + std::to_string(getpid()) + "-";
  // This launch's steps still listed, "ID NAME" each.
  auto ours = [&] {
    std::vector<std::pair<std::string, std::string>> found;
    auto steps =
        commandOutput({"squeue", "--noheader", "--steps", "--jobs", job, "--format=%i %j"});
    std::istringstream lines(steps ? *steps : std::string());
    for (std::string id, name; lines >> id >> name;) {
      if (name.rfind(prefix, 0) == 0) found.emplace_back(id, name);
    }
    return found;
  };
  auto left = ours();
  for (const auto& [id, name] : left) {
    std::fprintf(stderr, "vrflow: cancelling slurm step %s (%s)\n", id.c_str(), name.c_str());
    [[maybe_unused]] auto cancelled = commandOutput({"scancel", "--quiet", id});
  }
  // Gone once slurmctld says so (10 s at most: KillWait may let a task take its time).
  const auto begin = Clock::now();
  while (!left.empty() && secondsSince(begin) < 10) {
    usleep(200'000);
    left = ours();
  }
  for (const auto& [id, name] : left) {
    std::fprintf(stderr, "vrflow: slurm step %s (%s) is still listed after scancel\n", id.c_str(),
                 name.c_str());
  }
}

}  // namespace vrflow::launcher::detail
