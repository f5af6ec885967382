// vrflow-bench-patterns: the network patterns of issue 7, run for real with `vrflow run` on this
// host, one JSON line per case.
//
//   {"pattern":"broadcast","mode":"flat"|"tree","receivers":N,"ms_to_last":X,"source_host_bytes":B}
//     core/source sends `messages` messages of 1 MiB to N broadcast/checker receivers, directly
//     (flat: N connections from the source's output) or through a binary tree of broadcast
//     filters (the heap of examples/tree_broadcast). ms_to_last: for each message, the latency
//     from its send-time stamp to the last receiver that got it; the median over the messages
//     (the machine is shared: a mean follows the scheduler's worst moments).
//     source_host_bytes: the bytes the source's output filter forwarded (the report's bytes of
//     the connections from src.out). Everything runs on one host here, so this counts what the
//     source sends itself; the tree's filters would be on other hosts in a distributed run.
//   {"pattern":"routing","mode":"none"|"dynamic","viewers":4,"bytes_per_iteration":B}
//     routing/movers (a synthetic scene of moving rigid bodies over a 40 m wide world) to 4
//     routing/tile-viewers, each a quarter of the world along x, directly (none) or through a
//     route filter (dynamic). B: bytes delivered to the 4 viewers together per iteration (the
//     report's bytes of their input connections / iterations).
//   {"pattern":"routing","mode":"none"|"dynamic","viewers":4,"bytes_per_iteration":B,
//    "scene":"demo","tiles":[B0,B1,B2,B3]}
//     examples/routed_wall: the demo scene on a 2 x 2 wall of viewer/viewer tiles, fed straight
//     from the animators (direct_wall.xml, none) or through one route filter (routed_wall.xml,
//     dynamic), `demo-iterations` iterations, tiles drawn at 96 x 54 (the bytes do not depend on
//     the image size). Bk: bytes to tile k per iteration. Needs the node packages (skipped,
//     with a note, when vrflow-viewer is not built).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct Context {
  fs::path bin;       // folder of vrflow and the example modules
  fs::path packages;  // build/share/vrflow/example-packages
  fs::path work;      // scratch folder
  int hosts = 1;      // > 1: `vrflow launch --backend local` over 127.0.0.1 ... 127.0.0.H
};

std::string hostId(int h) {
  return "h" + std::to_string(h);
}

// The <hosts> element of ctx.hosts loopback hosts, or nothing for one host.
std::string hostsXml(const Context& ctx) {
  if (ctx.hosts < 2) return "";
  std::string xml = "  <hosts>\n";
  for (int h = 0; h < ctx.hosts; ++h) {
    xml +=
        "    <host id=\"" + hostId(h) + "\" address=\"127.0.0." + std::to_string(h + 1) + "\"/>\n";
  }
  return xml + "  </hosts>\n";
}

// ` host="hK"` for a node on host k, or nothing for one host.
std::string onHost(const Context& ctx, int k) {
  return ctx.hosts < 2 ? "" : " host=\"" + hostId(k % ctx.hosts) + "\"";
}

std::string q(const std::string& s) {
  return "'" + s + "'";
}

// Runs `vrflow run app` in ctx.work; the report as JSON, or an error.
bool runApp(const Context& ctx, const std::string& name, const std::string& xml,
            nlohmann::json& report) {
  const fs::path app = ctx.work / (name + ".xml");
  const fs::path reportFile = ctx.work / (name + ".json");
  std::ofstream(app) << xml;
  fs::remove(reportFile);
  const std::string command =
      "cd " + q(ctx.work.string()) + " && " + q((ctx.bin / "vrflow").string()) + " --packages " +
      q(ctx.packages.string()) +
      (ctx.hosts > 1 ? " launch --backend local " : " run --no-progress --shm-size 1024 ") +
      q(app.string()) + " --timeout 120 --report " + q(reportFile.string()) + " > " +
      q(name + ".log") + " 2>&1";
  const int status = std::system(command.c_str());
  if (status != 0) {
    std::fprintf(stderr, "vrflow-bench-patterns: %s failed (status %d); see %s\n", name.c_str(),
                 status, (ctx.work / (name + ".log")).c_str());
    return false;
  }
  std::ifstream in(reportFile);
  report = nlohmann::json::parse(in, nullptr, false);
  return !report.is_discarded();
}

std::string header(const std::string& name) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"" + name +
         "\" version=\"1\">\n";
}

std::string param(const std::string& name, const std::string& value) {
  return "      <param name=\"" + name + "\" value=\"" + value + "\"/>\n";
}

std::string connection(const std::string& from, const std::string& to) {
  return "    <connection from=\"" + from + "\" to=\"" + to + "\"/>\n";
}

double bytesFrom(const nlohmann::json& report, const std::string& prefix, bool toSide = false) {
  double total = 0;
  for (const auto& c : report["connections"]) {
    const std::string endpoint = c[toSide ? "to" : "from"].get<std::string>();
    if (endpoint.rfind(prefix, 0) == 0) total += c["bytes"].get<double>();
  }
  return total;
}

// Over H hosts the source is on h0 and the receivers in contiguous blocks on h1 ... h{H-1}
// (receiver i on h{1 + i (H-1) / n}); a tree filter is on the host of the first receiver below
// it, so each subtree stays on one host as far as it can and a message crosses the network
// about once per host, against once per receiver when flat.
int receiverHost(const Context& ctx, int i, int n) {
  return ctx.hosts < 2 ? 0 : 1 + i * (ctx.hosts - 1) / n;
}

int filterHost(const Context& ctx, int x, int m, int n, int fanout) {
  while (x < m) x = fanout * x + 1;  // leftmost child until a receiver (heap nodes m ... m+n-1)
  return receiverHost(ctx, std::min(x - m, n - 1), n);
}

bool broadcast(const Context& ctx, const std::string& mode, int n, int messages, int fanout) {
  std::string modules = "  <modules>\n    <module id=\"src\" package=\"core\" type=\"source\"" +
                        onHost(ctx, 0) + ">\n" + param("size", "1048576") +
                        param("count", std::to_string(messages)) + "    </module>\n";
  std::string filters, connections;
  for (int i = 0; i < n; ++i) {
    modules += "    <module id=\"r" + std::to_string(i) +
               "\" package=\"broadcast\" type=\"checker\"" + onHost(ctx, receiverHost(ctx, i, n)) +
               ">\n" + param("file", "received" + std::to_string(i) + ".csv") + "    </module>\n";
  }
  if (mode == "flat") {
    for (int i = 0; i < n; ++i)
      connections += connection("src.out", "r" + std::to_string(i) + ".in");
  } else {
    const int m = (n + fanout - 3) / (fanout - 1);  // broadcast filters: a heap, as the composite
    for (int k = 0; k < m; ++k)
      filters += "    <filter id=\"b" + std::to_string(k) + "\" type=\"broadcast\"" +
                 onHost(ctx, filterHost(ctx, k, m, n, fanout)) + "/>\n";
    connections += connection("src.out", "b0.in");
    for (int x = 1; x < m; ++x) {
      connections += connection("b" + std::to_string((x - 1) / fanout) + ".out",
                                "b" + std::to_string(x) + ".in");
    }
    for (int i = 0; i < n; ++i) {
      connections += connection("b" + std::to_string((m + i - 1) / fanout) + ".out",
                                "r" + std::to_string(i) + ".in");
    }
  }
  const std::string xml = header("broadcast") + hostsXml(ctx) + modules + "  </modules>\n" +
                          (filters.empty() ? "" : "  <filters>\n" + filters + "  </filters>\n") +
                          "  <connections>\n" + connections + "  </connections>\n</application>\n";
  nlohmann::json report;
  if (!runApp(ctx, "broadcast-" + mode + "-" + std::to_string(n), xml, report)) return false;
  std::map<long, double> last;  // message -> latest arrival (ns after send)
  for (int i = 0; i < n; ++i) {
    std::ifstream in(ctx.work / ("received" + std::to_string(i) + ".csv"));
    std::string line;
    std::getline(in, line);
    int rows = 0;
    while (std::getline(in, line)) {
      long counter = 0, size = 0;
      double latency = 0;
      if (std::sscanf(line.c_str(), "%ld,%ld,%lf", &counter, &size, &latency) != 3) continue;
      last[counter] = std::max(last[counter], latency);
      ++rows;
    }
    if (rows != messages) {
      std::fprintf(stderr, "vrflow-bench-patterns: receiver %d got %d of %d messages\n", i, rows,
                   messages);
      return false;
    }
  }
  std::vector<double> toLast;
  for (const auto& [counter, ns] : last) toLast.push_back(ns);
  std::sort(toLast.begin(), toLast.end());
  const double median = toLast.empty() ? 0 : toLast[toLast.size() / 2];
  std::printf(
      "{\"pattern\":\"broadcast\",\"mode\":\"%s\",\"receivers\":%d,\"hosts\":%d,\"ms_to_last\":%."
      "3f,"
      "\"source_host_bytes\":%.0f}\n",
      mode.c_str(), n, ctx.hosts, median / 1e6, bytesFrom(report, "src.out"));
  std::fflush(stdout);
  return true;
}

bool routing(const Context& ctx, const std::string& mode, int bodies, int iterations) {
  std::string modules =
      "  <modules>\n    <module id=\"scene\" package=\"routing\" type=\"movers\">\n" +
      param("count", std::to_string(bodies)) + param("iterations", std::to_string(iterations)) +
      "      <input port=\"beginIt\" initial-messages=\"1\"/>\n    </module>\n";
  std::string connections;
  for (int k = 0; k < 4; ++k) {
    const std::string id = "tile" + std::to_string(k);
    modules +=
        "    <module id=\"" + id + "\" package=\"routing\" type=\"tile-viewer\">\n" +
        param("box", std::to_string(10 * k) + " -1 -1 " + std::to_string(10 * k + 10) + " 12 1") +
        "    </module>\n";
    if (mode == "none") {
      connections += connection("scene.objects", id + ".objects");
    } else {
      connections += connection("wall.out" + std::to_string(k), id + ".objects") +
                     connection(id + ".interest", "wall.interest" + std::to_string(k));
    }
    connections += connection(id + ".endIt", "scene.beginIt");
  }
  std::string filters;
  if (mode == "dynamic") {
    connections = connection("scene.objects", "wall.in") + connections;
    filters = "  <filters>\n    <filter id=\"wall\" type=\"route\">\n" + param("outputs", "4") +
              "    </filter>\n  </filters>\n";
  }
  const std::string xml = header("routing") + modules + "  </modules>\n" + filters +
                          "  <connections>\n" + connections + "  </connections>\n</application>\n";
  nlohmann::json report;
  if (!runApp(ctx, "routing-" + mode, xml, report)) return false;
  double bytes = 0;
  for (const auto& c : report["connections"]) {
    const std::string to = c["to"].get<std::string>();
    if (to.rfind("tile", 0) == 0 && to.find(".objects") != std::string::npos) {
      bytes += c["bytes"].get<double>();
    }
  }
  std::printf(
      "{\"pattern\":\"routing\",\"mode\":\"%s\",\"viewers\":4,\"bytes_per_iteration\":%.0f}\n",
      mode.c_str(), bytes / iterations);
  std::fflush(stdout);
  return true;
}

void replaceAll(std::string& text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
}

// The demo scene on examples/routed_wall's 2 x 2 wall: `scene` "demo" (direct_wall.xml,
// routed_wall.xml) or "demo-fluid" (direct_fluid_wall.xml, routed_fluid_wall.xml).
bool demoRouting(const Context& ctx, const std::string& scene, const std::string& mode,
                 int iterations) {
  const fs::path folder = fs::path(VRFLOW_SOURCE_DIR) / "examples" / "routed_wall";
  const std::string kind = scene == "demo" ? "" : "fluid_";
  std::ifstream in(folder / ((mode == "none" ? "direct_" : "routed_") + kind + "wall.xml"));
  if (!in) {
    std::fprintf(stderr, "vrflow-bench-patterns: cannot read the routed_wall example in %s\n",
                 folder.c_str());
    return false;
  }
  std::stringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  replaceAll(xml, "\"../paper_scene/",
             "\"" + (folder.parent_path() / "paper_scene").string() + "/");
  replaceAll(xml, param("width", "480"), param("width", "96"));
  replaceAll(xml, param("height", "270"), param("height", "54"));
  const std::string frames = (ctx.work / ("frames-" + scene + "-" + mode)).string();
  for (const char* dir : {"routed-wall", "direct-wall", "routed-fluid-wall", "direct-fluid-wall"}) {
    replaceAll(xml, param("output-dir", dir),
               param("output-dir", frames) + param("format", "png") + param("supersample", "1"));
  }
  const std::string name = scene + "-routing-" + mode + "-" + std::to_string(iterations);
  const fs::path app = ctx.work / (name + ".xml");
  std::ofstream(app) << xml;
  const fs::path reportFile = ctx.work / (name + ".json");
  const std::string command = "cd " + q(ctx.work.string()) + " && " +
                              q((ctx.bin / "vrflow").string()) + " run " + q(app.string()) +
                              " -n " + std::to_string(iterations) +
                              " --no-progress --timeout 600 --report " + q(reportFile.string()) +
                              " > " + q(name + ".log") + " 2>&1";
  if (const int status = std::system(command.c_str()); status != 0) {
    std::fprintf(stderr, "vrflow-bench-patterns: %s failed (status %d); see %s\n", name.c_str(),
                 status, (ctx.work / (name + ".log")).c_str());
    return false;
  }
  nlohmann::json report;
  std::ifstream(reportFile) >> report;
  std::vector<double> tiles(4, 0.0);
  for (const auto& c : report["connections"]) {
    const std::string to = c["to"].get<std::string>();
    const std::string tile = to.substr(0, to.find('.'));
    for (std::size_t k = 0; k < tiles.size(); ++k) {
      if (tile == "tile" + std::to_string(k) && to == tile + ".objects") {
        tiles[k] += c["bytes"].get<double>();
      }
    }
  }
  double total = 0;
  for (const double b : tiles) total += b;
  std::printf(
      "{\"pattern\":\"routing\",\"mode\":\"%s\",\"viewers\":4,\"bytes_per_iteration\":%.0f,"
      "\"scene\":\"%s\",\"tiles\":[%.0f,%.0f,%.0f,%.0f]}\n",
      mode.c_str(), total / iterations, scene.c_str(), tiles[0] / iterations, tiles[1] / iterations,
      tiles[2] / iterations, tiles[3] / iterations);
  std::fflush(stdout);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"vrflow-bench-patterns: broadcast (flat vs tree) and routing (none vs dynamic)"};
  std::string receiversText = "2,4,8,16";
  int messages = 50, fanout = 2, bodies = 256, iterations = 200, demoIterations = 300;
  bool quick = false;
  std::string only;
  cli.add_option("--receivers", receiversText, "broadcast receiver counts, comma-separated");
  cli.add_option("--messages", messages, "1 MiB messages per broadcast case")
      ->check(CLI::Range(1, 100000));
  cli.add_option("--fanout", fanout, "fan-out of the broadcast tree")->check(CLI::Range(2, 256));
  cli.add_option("--bodies", bodies, "bodies of the routing scene")->check(CLI::Range(1, 1000000));
  cli.add_option("--iterations", iterations, "routing iterations")->check(CLI::Range(2, 1000000));
  cli.add_option("--demo-iterations", demoIterations, "iterations of the demo scene's wall")
      ->check(CLI::Range(2, 1000000));
  cli.add_option("--pattern", only, "broadcast or routing (default: both)")
      ->check(CLI::IsMember({"broadcast", "routing"}));
  int hosts = 1;
  cli.add_option("--hosts", hosts,
                 "broadcast over this many loopback hosts (vrflow launch --backend local; the "
                 "source on the first, receivers and tree filters on the others)")
      ->check(CLI::Range(1, 254));
  cli.add_flag("--quick", quick,
               "a small run (2 and 4 receivers, 5 messages, 20 iterations of each scene)");
  CLI11_PARSE(cli, argc, argv);
  if (quick) {
    receiversText = "2,4";
    messages = 5;
    iterations = 20;
    demoIterations = 20;
  }
  std::vector<int> receivers;
  std::stringstream list(receiversText);
  for (std::string item; std::getline(list, item, ',');) {
    const int n = std::atoi(item.c_str());
    if (n < 2 || n > 4096) {
      std::fprintf(stderr, "vrflow-bench-patterns: --receivers: %s is not in [2, 4096]\n",
                   item.c_str());
      return 2;
    }
    receivers.push_back(n);
  }

  Context ctx;
  ctx.bin = fs::canonical("/proc/self/exe").parent_path();
  ctx.packages = ctx.bin.parent_path() / "share" / "vrflow" / "example-packages";
  char scratch[] = "/tmp/vrflow-bench-patterns-XXXXXX";
  if (mkdtemp(scratch) == nullptr) {
    std::perror("vrflow-bench-patterns: mkdtemp");
    return 1;
  }
  ctx.work = scratch;
  ctx.hosts = hosts;
  bool ok = true;
  if (only.empty() || only == "broadcast") {
    for (const int n : receivers) {
      for (const char* mode : {"flat", "tree"})
        ok = broadcast(ctx, mode, n, messages, fanout) && ok;
    }
  }
  if (only.empty() || only == "routing") {
    Context oneHost = ctx;
    oneHost.hosts = 1;  // the routing cases count bytes, which hosts do not change
    for (const char* mode : {"none", "dynamic"})
      ok = routing(oneHost, mode, bodies, iterations) && ok;
    if (fs::exists(ctx.bin / "vrflow-viewer")) {
      for (const char* mode : {"none", "dynamic"})
        ok = demoRouting(oneHost, "demo", mode, demoIterations) && ok;
      if (fs::exists(ctx.bin / "vrflow-fluid") &&
          fs::exists(fs::path(VRFLOW_SOURCE_DIR) / "examples" / "routed_wall" /
                     "routed_fluid_wall.xml")) {
        for (const char* mode : {"none", "dynamic"})
          ok = demoRouting(oneHost, "demo-fluid", mode, demoIterations) && ok;
      }
    } else {
      std::fprintf(stderr,
                   "vrflow-bench-patterns: no vrflow-viewer beside this program (node "
                   "packages off): the demo scene's routing is skipped\n");
    }
  }
  std::error_code ignored;
  fs::remove_all(ctx.work, ignored);
  return ok ? 0 : 1;
}
