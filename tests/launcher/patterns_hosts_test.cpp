// Every network pattern of issue 7 under a 3-host `vrflow launch --backend local`: each example
// is flattened (composites expanded), its modules and filters dealt round-robin over hosts a, b
// and c (127.0.0.1-3, one daemon each, TCP between them), and run. A pattern must give what it
// gives on one host: the same final digests of every output, and its own semantics (every
// message once and in order through a tree; 10 inner steps per outer one; ...).
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "app_text.hpp"
#include "process_helpers.hpp"
#include "vrflow/app/expand.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/writer.hpp"

namespace vrflow::testing {
namespace {

std::string examplePackages() {
  return binDir() + "/../share/vrflow/example-packages";
}

// The flat application of `source` with its modules and filters spread over 3 hosts, saved as
// `dir/name`; returns the hosts each node got.
std::map<std::string, std::string> spreadOverThreeHosts(const std::string& source,
                                                        const TempDir& dir,
                                                        const std::string& name) {
  auto application = app::loadApplicationFile(source);
  EXPECT_TRUE(application) << application.error().message;
  if (!application) return {};
  auto flat = app::expandComposites(*application, app::defaultCompositeSources(*application));
  EXPECT_TRUE(flat) << flat.error().message;
  if (!flat) return {};
  flat->hosts = {{"a", "127.0.0.1", {}}, {"b", "127.0.0.2", {}}, {"c", "127.0.0.3", {}}};
  std::map<std::string, std::string> placed;
  std::size_t next = 0;
  const char* hosts[] = {"a", "b", "c"};
  for (auto& m : flat->modules) placed[m.id] = m.host = hosts[next++ % 3];
  for (auto& f : flat->filters) placed[f.id] = f.host = hosts[next++ % 3];
  flat->editor.clear();
  flat->file.clear();
  const auto saved = app::saveApplicationFile(*flat, dir.file(name));
  EXPECT_TRUE(saved) << saved.error().message;
  return placed;
}

// `vrflow COMMAND APP ARGS` from `dir` (outputs land there), with the example packages.
CommandResult vrflowIn(const TempDir& dir, const std::string& command, const std::string& app,
                       const std::string& args) {
  return runCommand(
      {"/bin/sh", "-c",
       "cd '" + dir.path() + "' && exec '" + binDir() + "/vrflow' --packages '" +
           examplePackages() + "' --packages '" + binDir() + "/../test-packages' " + command +
           " '" + app + "' " + args + (command == "run" ? " --no-progress" : "") + " --timeout 90"},
      150);
}

// The last digest of every output, of the modules `keep` accepts. Object ids carry the host
// that made them (docs/message-layout.md), so only the outputs of modules on host a (127.0.0.1,
// the address of the one-host run) can be compared bit for bit; the others are compared by
// what they recorded, ids aside.
std::map<std::string, std::string> lastDigests(const TempDir& dir, const std::string& report,
                                               const std::set<std::string>* keep = nullptr) {
  const auto json = nlohmann::json::parse(readFile(dir.file(report)));
  EXPECT_EQ(json["status"], "ok");
  std::map<std::string, std::string> digests;
  for (const auto& o : json["outputs"]) {
    if (keep != nullptr && keep->count(o["module"].get<std::string>()) == 0) continue;
    digests[o["module"].get<std::string>() + "." + o["port"].get<std::string>()] =
        o["last_digest"].get<std::string>();
  }
  return digests;
}

std::map<std::string, long> iterationsOf(const TempDir& dir, const std::string& report) {
  const auto json = nlohmann::json::parse(readFile(dir.file(report)));
  std::map<std::string, long> iterations;
  for (const auto& m : json["modules"]) iterations[m["id"]] = m["iterations"].get<long>();
  return iterations;
}

std::set<std::string> hostsUsed(const std::map<std::string, std::string>& placed) {
  std::set<std::string> used;
  for (const auto& [node, host] : placed) used.insert(host);
  return used;
}

// Runs `example` on one host and on three, and checks that every output ends with the same
// digest; returns the folder of the 3-host run for pattern-specific checks.
void expectSameOnThreeHosts(const std::string& example, const TempDir& one, const TempDir& three,
                            const std::string& args = "") {
  const std::string source = sourceDir() + "/examples/" + example;
  const auto placed = spreadOverThreeHosts(source, three, "three.xml");
  ASSERT_EQ(hostsUsed(placed).size(), 3u);
  const auto a = vrflowIn(one, "run", source, args + " --report one.json");
  ASSERT_EQ(a.exitCode, 0) << a.err;
  const auto b = vrflowIn(three, "launch", three.file("three.xml"),
                          args + " --backend local --report three.json");
  ASSERT_EQ(b.exitCode, 0) << b.err;
  std::set<std::string> onA;
  for (const auto& [node, host] : placed) {
    if (host == "a") onA.insert(node);
  }
  const auto digestsOne = lastDigests(one, "one.json", &onA);
  EXPECT_FALSE(digestsOne.empty());
  EXPECT_EQ(digestsOne, lastDigests(three, "three.json", &onA)) << example;
  EXPECT_EQ(iterationsOf(one, "one.json"), iterationsOf(three, "three.json")) << example;
}

// A recorder's CSV without its id column (iteration,source,source_iteration,sim_time,kind,id,...).
std::string withoutIds(const std::string& path) {
  std::string result;
  for (const auto& line : readLines(path)) {
    std::stringstream in(line);
    std::string field;
    for (int column = 0; std::getline(in, field, ','); ++column) {
      if (column != 5) result += field + ",";
    }
    result += "\n";
  }
  return result;
}

class PatternsOnThreeHosts : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  TempDir one, three;
};

TEST_F(PatternsOnThreeHosts, TreeBroadcastDeliversEveryMessageOnceInOrder) {
  expectSameOnThreeHosts("tree_broadcast/tree_broadcast.xml", one, three);
  for (int r = 0; r < 8; ++r) {
    const auto lines = readLines(three.file("received" + std::to_string(r) + ".csv"));
    ASSERT_EQ(lines.size(), 21u) << "receiver " << r;
    for (int i = 0; i < 20; ++i) {
      EXPECT_EQ(lines[static_cast<std::size_t>(i) + 1].substr(0, lines[i + 1].find(',')),
                std::to_string(i))
          << "receiver " << r;
    }
  }
}

TEST_F(PatternsOnThreeHosts, MultiRateRunsTenInnerStepsPerOuterOne) {
  expectSameOnThreeHosts("multi_rate/multi_rate.xml", one, three, "--iterations 6");
  const auto iterations = iterationsOf(three, "three.json");
  EXPECT_EQ(iterations.at("outer"), 6);
  EXPECT_EQ(iterations.at("net"), 60);
  EXPECT_EQ(readLines(three.file("inner.csv")).size(), 61u);
  EXPECT_EQ(readLines(three.file("outer.csv")).size(), 7u);
  EXPECT_EQ(withoutIds(one.file("outer.csv")), withoutIds(three.file("outer.csv")));
  EXPECT_EQ(withoutIds(one.file("inner.csv")), withoutIds(three.file("inner.csv")));
}

TEST_F(PatternsOnThreeHosts, DynamicRoutingSendsEachTileTheSameAsOnOneHost) {
  expectSameOnThreeHosts("dynamic_routing/dynamic_routing.xml", one, three, "--iterations 60");
  // Same chunks to each tile: the bytes on every connection into a tile are those of one host.
  const auto bytesInto = [](const TempDir& dir, const std::string& report) {
    std::map<std::string, uint64_t> bytes;
    // The parsed report outlives the loop (a range over a member of a temporary would not).
    const auto parsed = nlohmann::json::parse(readFile(dir.file(report)));
    for (const auto& c : parsed["connections"]) {
      bytes[c["from"].get<std::string>() + "->" + c["to"].get<std::string>()] =
          c["bytes"].get<uint64_t>();
    }
    return bytes;
  };
  EXPECT_EQ(bytesInto(one, "one.json"), bytesInto(three, "three.json"));
}

TEST_F(PatternsOnThreeHosts, DuplicatedInteractorGivesTheDigestOfOneCopy) {
  expectSameOnThreeHosts("duplicated_interactor/duplicated_gravity.xml", one, three,
                         "--iterations 100");
  const auto single =
      vrflowIn(one, "run", sourceDir() + "/examples/duplicated_interactor/one_gravity.xml",
               "--iterations 100 --report single.json");
  ASSERT_EQ(single.exitCode, 0) << single.err;
  EXPECT_EQ(lastDigests(one, "single.json").at("chain.objects"),
            lastDigests(three, "three.json").at("chain.objects"));
}

// Type filter across hosts: points and resources merged on b, the points kept on c, recorded
// on a; the recorded stream is that of one host. (The gate examples are left out: a gate's
// output depends on whether the control or the data message arrives first, which a network
// does not preserve between two paths.)
TEST_F(PatternsOnThreeHosts, TypeFilterKeepsTheSameChunksAcrossHosts) {
  const std::string xml = R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="types" version="1">
  <hosts><host id="a" address="127.0.0.1"/><host id="b" address="127.0.0.2"/><host id="c" address="127.0.0.3"/></hosts>
  <modules>
    <module id="chain" package="core" type="points" host="a"><param name="count" value="4"/></module>
    <module id="blobs" package="core" type="source" host="b"><param name="count" value="30"/></module>
    <module id="rec" package="core" type="recorder" host="a"><param name="file" value="kept.csv"/></module>
  </modules>
  <filters>
    <filter id="both" type="merge" host="b"><param name="inputs" value="2"/></filter>
    <filter id="points" type="typefilter" host="c">
      <param name="types" value="point"/><param name="drop-others" value="true"/>
    </filter>
  </filters>
  <connections>
    <connection from="chain.objects" to="both.in0"/>
    <connection from="blobs.out" to="both.in1"/>
    <connection from="both.out" to="points.in"/>
    <connection from="points.out" to="rec.in"/>
  </connections>
</application>
)";
  for (const TempDir* dir : {&one, &three}) {
    std::ofstream(dir->file("types.xml")) << xml;
  }
  const auto a = vrflowIn(one, "run", one.file("types.xml"), "--iterations 30 --report one.json");
  ASSERT_EQ(a.exitCode, 0) << a.err;
  const auto b = vrflowIn(three, "launch", three.file("types.xml"),
                          "--iterations 30 --backend local --report three.json");
  ASSERT_EQ(b.exitCode, 0) << b.err;
  const auto kept = withoutIds(three.file("kept.csv"));
  EXPECT_EQ(withoutIds(one.file("kept.csv")), kept);
  EXPECT_EQ(kept.find("resource"), std::string::npos) << "the source's resources are dropped";
  EXPECT_EQ(readLines(three.file("kept.csv")).size(), 1u + 30u * 4u) << "4 points x 30 iterations";
}

// Greedy sampling across hosts: a writer of 2,000 messages on one host, a reader 10x slower on
// another; the writer never waits (it finishes all of them), the reader's samples increase and
// end with the last one, no buffer stays full.
TEST_F(PatternsOnThreeHosts, GreedySamplingNeverBlocksTheWriterAcrossHosts) {
  const std::string xml = R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="greedy" version="1">
  <hosts><host id="a" address="127.0.0.1"/><host id="b" address="127.0.0.2"/><host id="c" address="127.0.0.3"/></hosts>
  <modules>
    <module id="fast" package="core" type="source" host="a"><param name="size" value="4096"/><param name="count" value="2000"/></module>
    <module id="slow" package="testing" type="slow" host="c"><param name="delay-ms" value="5"/></module>
    <module id="rec" package="core" type="recorder" host="c"><param name="file" value="sampled.csv"/></module>
  </modules>
  <filters><filter id="sample" type="latest" host="b"/></filters>
  <connections>
    <connection from="fast.out" to="sample.in"/>
    <connection from="sample.out" to="slow.in"/>
    <connection from="slow.endIt" to="sample.sync"/>
    <connection from="slow.out" to="rec.in"/>
  </connections>
</application>
)";
  const std::string file = three.file("greedy.xml");
  {
    std::ofstream out(file);
    out << xml;
  }
  const auto result = vrflowIn(three, "launch", file, "--backend local --report three.json");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto iterations = iterationsOf(three, "three.json");
  EXPECT_EQ(iterations.at("fast"), 2000);
  EXPECT_LT(iterations.at("slow"), 2000);
  EXPECT_GE(iterations.at("slow"), 1);
  const auto report = nlohmann::json::parse(readFile(three.file("three.json")));
  for (const auto& c : report["connections"]) {
    EXPECT_EQ(c["stayed_full"], false) << c["from"];
  }
  const auto counters = recordedCounters(three.file("sampled.csv"));
  ASSERT_FALSE(counters.empty());
  for (std::size_t i = 1; i < counters.size(); ++i) EXPECT_GT(counters[i], counters[i - 1]);
  EXPECT_EQ(counters.back(), 1999) << "the newest message is the last one read";
}

}  // namespace
}  // namespace vrflow::testing
