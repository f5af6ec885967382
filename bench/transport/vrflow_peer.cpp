// The vrflow side of the transport benchmark: two module processes exchanging messages through
// the per-host daemon with the default filters, on the same plan as the other transports.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "transport_bench.hpp"
#include "vrflow/app/catalog.hpp"
#include "vrflow/run/runner.hpp"

namespace vrflow::bench {
namespace {

namespace fs = std::filesystem;

app::Module peer(const std::string& id, std::vector<app::Param> params) {
  app::Module module;
  module.id = id;
  module.package = "bench";
  module.type = "peer";
  module.params = std::move(params);
  return module;
}

app::Connection connection(const std::string& from, const std::string& to) {
  app::Connection c;
  c.from = *app::parseEndpoint(from);
  c.to = *app::parseEndpoint(to);
  return c;
}

Result<app::Catalog> benchCatalog() {
  std::vector<char> self(4096, '\0');
  const ssize_t length = readlink("/proc/self/exe", self.data(), self.size() - 1);
  if (length <= 0) return makeError("cannot find this executable's folder");
  app::ModuleType type;
  type.package = "bench";
  type.type = "peer";
  type.executable =
      (fs::path(std::string(self.data(), static_cast<std::size_t>(length))).parent_path() /
       "vrflow-bench-peer")
          .string();
  app::PortSpec in;
  in.name = "in";
  in.isInput = true;
  app::PortSpec out;
  out.name = "out";
  out.isInput = false;
  type.ports = {in, out};
  // The same declarations as the manifest tcp_peers.cpp writes for `vrflow launch`.
  struct Declared {
    const char* name;
    app::ParamType type;
    const char* defaultValue;
  };
  for (const Declared& declared :
       {Declared{"role", app::ParamType::String, "pong"},
        Declared{"size", app::ParamType::Int, "64"}, Declared{"warmup", app::ParamType::Int, "0"},
        Declared{"results", app::ParamType::File, ""},
        Declared{"count", app::ParamType::Int, "0"}}) {
    app::ParamSpec spec;
    spec.name = declared.name;
    spec.type = declared.type;
    spec.defaultValue = declared.defaultValue;
    type.params.push_back(spec);
  }
  app::Catalog catalog;
  if (auto status = catalog.addModuleType(type); !status) return status.error();
  return catalog;
}

Status runOnce(const app::Application& application, const app::Catalog& catalog,
               const BenchSettings& settings) {
  run::RunOptions options;
  options.timeoutSeconds = static_cast<double>(settings.peerTimeout.count()) / 1000.0;
  options.segmentBytes = std::size_t{2} << 30;
  const auto outcome = run::runApplication(application, catalog, options);
  if (outcome.exitCode != 0) return makeError("vrflow-shm: " + outcome.error);
  return {};
}

}  // namespace

Result<BenchResult> readPeerResult(const std::string& transport, std::size_t bytes,
                                   const std::string& rttFile, const std::string& rateFile,
                                   std::string detail) {
  std::vector<std::int64_t> samples;
  std::ifstream rtt(rttFile);
  for (std::int64_t ns = 0; rtt >> ns;) samples.push_back(ns);
  double msgsPerS = 0;
  std::ifstream(rateFile) >> msgsPerS;
  if (samples.empty()) {
    return makeError(transport + ": no round trip measured at " + std::to_string(bytes) + " bytes");
  }
  return makeResult(transport, bytes, samples, msgsPerS, std::move(detail));
}

Result<std::vector<BenchResult>> forEachSize(
    const BenchSettings& settings,
    const std::function<Result<BenchResult>(std::size_t bytes)>& runSize) {
  std::vector<BenchResult> results;
  for (const std::size_t bytes : settings.sizes) {
    auto result = runSize(bytes);
    if (!result) return result.error();
    results.push_back(std::move(*result));
  }
  return results;
}

Result<std::vector<BenchResult>> runEachSize(
    const BenchSettings& settings, const std::filesystem::path& dir,
    const std::function<Result<BenchResult>(std::size_t bytes)>& runSize) {
  auto results = forEachSize(settings, runSize);
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  return results;
}

Result<std::vector<BenchResult>> runVrflow(const BenchSettings& settings) {
  auto catalog = benchCatalog();
  if (!catalog) return catalog.error();
  char pattern[] = "/tmp/vrflow-bench-XXXXXX";
  if (mkdtemp(pattern) == nullptr) return makeError("cannot make a temporary folder");
  const fs::path dir(pattern);
  return runEachSize(settings, dir, [&](std::size_t bytes) -> Result<BenchResult> {
    const IterationPlan plan = iterationPlan(bytes, settings.quick);
    const std::string size = std::to_string(bytes);
    const std::string warmup = std::to_string(plan.warmupMessages);

    // Ping-pong: a cycle started by one initial message on ping's input.
    const auto rtt = (dir / ("rtt-" + size)).string();
    app::Application pingPong;
    pingPong.name = "bench-ping-pong";
    pingPong.modules = {peer("ping", {{"role", "ping", {}},
                                      {"size", size, {}},
                                      {"warmup", warmup, {}},
                                      {"results", rtt, {}}}),
                        peer("pong", {{"role", "pong", {}}})};
    app::InputConfig start;
    start.port = "in";
    start.initialMessages = 1;
    pingPong.modules[0].inputs.push_back(start);
    pingPong.connections = {connection("ping.out", "pong.in"), connection("pong.out", "ping.in")};
    // ping runs warmup + timed iterations, then ends; pong ends when its input does.
    pingPong.modules[0].params.push_back(
        {"count", std::to_string(plan.warmupMessages + plan.pingPongs + 1), {}});
    // The iteration limit is per run, so ping stops itself by count: see vrflow_bench_module.
    if (Status ran = runOnce(pingPong, *catalog, settings); !ran) return ran.error();

    // Streaming: send -> recv with backpressure, queue depth as the peers use it.
    const auto rate = (dir / ("rate-" + size)).string();
    app::Application stream;
    stream.name = "bench-stream";
    stream.modules = {
        peer("send", {{"role", "send", {}},
                      {"size", size, {}},
                      {"count", std::to_string(plan.warmupMessages + plan.streamMessages), {}}}),
        peer("recv", {{"role", "recv", {}}, {"warmup", warmup, {}}, {"results", rate, {}}})};
    auto link = connection("send.out", "recv.in");
    link.capacity = static_cast<int>(streamQueueDepth(bytes));
    stream.connections = {link};
    if (Status ran = runOnce(stream, *catalog, settings); !ran) return ran.error();

    return readPeerResult("vrflow-shm", bytes, rtt, rate,
                          "module -> daemon -> module over a memfd segment, default "
                          "filters, futex wake-ups; payload re-sent by handle");
  });
}

}  // namespace vrflow::bench
