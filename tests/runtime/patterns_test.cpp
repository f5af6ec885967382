// End-to-end tests of the network patterns (issue 7, one host): multi-rate (repeat, decimate),
// tree broadcast (composite of broadcast filters), dynamic routing by bounding volume (route),
// module duplication (composite of scatter + copies + gather). Each runs the real `vrflow`.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "app_text.hpp"
#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream in(line);
  for (std::string field; std::getline(in, field, ',');) f.push_back(field);
  if (!line.empty() && line.back() == ',') f.emplace_back();
  return f;
}

class Patterns : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  // `vrflow run APP` from the temporary folder, with the example packages and composites.
  CommandResult run(const std::string& app, const std::string& extra = "") {
    return runCommand({"/bin/sh", "-c",
                       "cd " + dir.path() + " && " + binDir() + "/vrflow --packages " + binDir() +
                           "/../share/vrflow/example-packages run " + app +
                           " --no-progress --timeout 60 " + extra},
                      90);
  }
  std::string example(const std::string& path) { return sourceDir() + "/examples/" + path; }
  // routing/movers (with `params`, paced by the viewers) through one route filter `wall` to a
  // routing/tile-viewer per box, v0 ... (each logging to vK.csv in the temporary folder).
  std::string moversWall(const std::string& params, const std::vector<std::string>& boxes) {
    std::string modules =
        moduleXml("scene", "routing/movers",
                  params + "      <input port=\"beginIt\" initial-messages=\"1\"/>\n");
    std::string connections = connectXml("scene.objects", "wall.in");
    for (std::size_t k = 0; k < boxes.size(); ++k) {
      const std::string id = "v" + std::to_string(k);
      modules += moduleXml(id, "routing/tile-viewer",
                           paramXml("box", boxes[k]) + paramXml("file", dir.file(id + ".csv")));
      connections += connectXml("wall.out" + std::to_string(k), id + ".objects") +
                     connectXml(id + ".interest", "wall.interest" + std::to_string(k)) +
                     connectXml(id + ".endIt", "scene.beginIt");
    }
    return appXml(modules,
                  filterXml("wall", "route", paramXml("outputs", std::to_string(boxes.size()))),
                  connections);
  }
  nlohmann::json report(const std::string& name) {
    return nlohmann::json::parse(readFile(dir.file(name)));
  }
  TempDir dir;
};

// ---- multi-rate ----------------------------------------------------------------------------

struct State {
  long sourceIteration;
  double simTime;
  double x;
};

std::vector<State> states(const std::string& csv) {
  std::vector<State> result;
  const auto lines = readLines(csv);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const auto f = fields(lines[i]);  // iteration,source,source_iteration,sim_time,kind,id,x,y,z
    EXPECT_GE(f.size(), 9u) << lines[i];
    if (f.size() < 9) continue;
    result.push_back({std::stol(f[2]), std::stod(f[3]), std::stod(f[6])});
  }
  return result;
}

// examples/multi_rate: a spring of k = 225 (omega = 15 rad/s) driven by an outer loop of
// dt = 0.2 s. omega * dt = 3 is beyond semi-implicit Euler's limit of 2; omega * dt / 10 = 0.3
// is well inside it.
TEST_F(Patterns, MultiRateRunsTenInnerStepsOfDtOverTenPerOuterStep) {
  const auto result = run(example("multi_rate/multi_rate.xml"));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto inner = states(dir.file("inner.csv"));
  const auto outer = states(dir.file("outer.csv"));
  ASSERT_EQ(inner.size(), 100u) << "10 outer iterations x 10 inner ones";
  ASSERT_EQ(outer.size(), 10u) << "decimate: one per outer iteration";
  for (std::size_t j = 0; j < inner.size(); ++j) {
    EXPECT_EQ(inner[j].sourceIteration, static_cast<long>(j));
    // repeat stamps copy j of outer message i with t = 0.2 i + 0.02 j and step 0.02; the
    // oscillator steps by the stamp's time step and stamps t + step.
    EXPECT_NEAR(inner[j].simTime, 0.02 * static_cast<double>(j + 1), 1e-9) << j;
  }
  for (std::size_t i = 0; i < outer.size(); ++i) {
    const double t = 0.2 * static_cast<double>(i + 1);
    EXPECT_EQ(outer[i].sourceIteration, static_cast<long>(i)) << "restamped: outer numbering";
    EXPECT_NEAR(outer[i].simTime, t, 1e-9);
    EXPECT_EQ(outer[i].x, inner[10 * i + 9].x) << "the last of each group of 10";
    EXPECT_LE(std::abs(outer[i].x), 1.05) << "stable: the energy stays bounded";
    EXPECT_NEAR(outer[i].x, std::cos(15.0 * t), 0.3) << "close to x0 cos(omega t) at t=" << t;
  }
}

// `--iterations N` counts outer iterations: the module behind repeat(10) runs 10 N, the ones
// behind decimate(10) N (app::iterationRates), so the outer side still gets its N states.
TEST_F(Patterns, IterationsCountOuterIterationsBehindRepeat) {
  const auto result = run(example("multi_rate/multi_rate.xml"), "--iterations 5 --report r.json");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto json = report("r.json");
  std::map<std::string, long> iterations;
  for (const auto& m : json["modules"]) iterations[m["id"]] = m["iterations"].get<long>();
  EXPECT_EQ(iterations["outer"], 5);
  EXPECT_EQ(iterations["net"], 50);
  EXPECT_EQ(iterations["inner_log"], 50);
  EXPECT_EQ(iterations["outer_log"], 5);
  EXPECT_EQ(states(dir.file("outer.csv")).size(), 5u);
}

// The paper's coupling: the slow module reads the fast one's decimated state (a cycle through
// repeat and decimate, started by one initial message on the slow side). Each outer iteration
// waits for the 10 inner ones; the states are those of the open chain.
TEST_F(Patterns, MultiRateLoopBackToTheSlowModuleRunsInLockstep) {
  const auto app = dir.write(
      "loop.xml",
      appXml(moduleXml("outer", "multirate/clock",
                       paramXml("dt", "0.2") + paramXml("count", "10") +
                           "      <input port=\"state\" initial-messages=\"1\"/>\n") +
                 moduleXml("net", "multirate/oscillator", paramXml("stiffness", "225")) +
                 moduleXml("log", "core/recorder", paramXml("file", "loop.csv")),
             filterXml("up", "repeat", paramXml("count", "10")) +
                 filterXml("down", "decimate", paramXml("count", "10")),
             connectXml("outer.ticks", "up.in") + connectXml("up.out", "net.clock") +
                 connectXml("net.state", "down.in") + connectXml("down.out", "outer.state") +
                 connectXml("down.out", "log.in")));
  const auto result = run(app, "--report report.json");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto json = report("report.json");
  std::map<std::string, long> iterations;
  for (const auto& m : json["modules"]) iterations[m["id"]] = m["iterations"].get<long>();
  EXPECT_EQ(iterations["outer"], 10);
  EXPECT_EQ(iterations["net"], 100);
  const auto loop = states(dir.file("loop.csv"));
  ASSERT_EQ(loop.size(), 10u);
  ASSERT_EQ(run(example("multi_rate/multi_rate.xml")).exitCode, 0);
  const auto open = states(dir.file("outer.csv"));
  ASSERT_EQ(open.size(), 10u);
  for (std::size_t i = 0; i < loop.size(); ++i) {
    EXPECT_EQ(loop[i].x, open[i].x);
    EXPECT_EQ(loop[i].simTime, open[i].simTime);
  }
}

TEST_F(Patterns, TheSameSpringStepRunAtTheOuterDtExplodes) {
  const auto app = dir.write(
      "single_rate.xml",
      appXml(
          moduleXml("outer", "multirate/clock", paramXml("dt", "0.2") + paramXml("count", "10")) +
              moduleXml("net", "multirate/oscillator", paramXml("stiffness", "225")) +
              moduleXml("log", "core/recorder", paramXml("file", "single.csv")),
          "", connectXml("outer.ticks", "net.clock") + connectXml("net.state", "log.in")));
  const auto result = run(app);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto single = states(dir.file("single.csv"));
  ASSERT_EQ(single.size(), 10u);
  EXPECT_NEAR(single.back().simTime, 2.0, 1e-9);
  // The exact answer stays within [-1, 1]; one step of 0.2 s amplifies by ~6.85 per step.
  EXPECT_GT(std::abs(single.back().x), 1e6) << "explodes where the 10x rate is stable";
}

TEST_F(Patterns, RepeatThenDecimateGivesBackTheStreamAndDecimateCanForwardByReference) {
  const auto app = dir.write(
      "roundtrip.xml",
      appXml(
          moduleXml("src", "core/source", paramXml("count", "12")) +
              moduleXml("relay", "core/relay") +
              moduleXml("rec", "core/recorder", paramXml("file", dir.file("out.csv"))),
          filterXml("up", "repeat", paramXml("count", "3")) +
              filterXml("down", "decimate", paramXml("count", "3") + paramXml("restamp", "false")),
          connectXml("src.out", "up.in") + connectXml("up.out", "relay.in") +
              connectXml("relay.out", "down.in") + connectXml("down.out", "rec.in")));
  ASSERT_EQ(run(app).exitCode, 0);
  const auto rows = readRecording(dir.file("out.csv"));
  ASSERT_EQ(rows.size(), 12u);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(std::stol(rows[i].x), static_cast<long>(i)) << "every source message once, in order";
    EXPECT_EQ(rows[i].source, "src") << "relay and decimate forward by reference";
    EXPECT_EQ(rows[i].sourceIteration, static_cast<long>(3 * i + 2)) << "repeat: iteration 3i+2";
  }
}

// ---- tree broadcast ------------------------------------------------------------------------

void expectEveryMessageOnceInOrder(const TempDir& dir, int receivers, long messages) {
  for (int r = 0; r < receivers; ++r) {
    const auto lines = readLines(dir.file("received" + std::to_string(r) + ".csv"));
    ASSERT_EQ(lines.size(), static_cast<std::size_t>(messages) + 1) << "receiver " << r;
    for (long i = 0; i < messages; ++i) {
      EXPECT_EQ(fields(lines[static_cast<std::size_t>(i) + 1]).at(0), std::to_string(i))
          << "receiver " << r;
    }
  }
}

TEST_F(Patterns, TreeBroadcastDeliversEveryMessageOnceInOrderToEveryReceiver) {
  const auto result = run(example("tree_broadcast/tree_broadcast.xml"), "--report report.json");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  expectEveryMessageOnceInOrder(dir, 8, 20);
  // A binary tree: the source sends once; no filter sends to more than 2.
  const auto json = report("report.json");
  std::map<std::string, int> fanOut;
  for (const auto& c : json["connections"]) {
    ++fanOut[c["from"].get<std::string>()];
    EXPECT_EQ(c["messages"], 20) << c["from"] << " -> " << c["to"];
  }
  EXPECT_EQ(fanOut["src.out"], 1);
  EXPECT_EQ(fanOut.size(), 8u) << "src and 7 broadcast filters";
  for (const auto& [from, count] : fanOut) EXPECT_LE(count, 2) << from;
}

TEST_F(Patterns, TreeBroadcastWithFanOutThreeAndAnUnevenCount) {
  auto text = readFile(example("tree_broadcast/tree_broadcast.xml"));
  const auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  };
  replace("name=\"n\" value=\"8\"", "name=\"n\" value=\"7\"");
  replace("name=\"fanout\" value=\"2\"", "name=\"fanout\" value=\"3\"");
  replace("name=\"count\" value=\"20\"", "name=\"count\" value=\"9\"");
  replace("value=\"1048576\"", "value=\"4096\"");
  const auto app = dir.write("tree3.xml", text);
  const auto result = run(app, "--report report.json --composites " + example("tree_broadcast"));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  expectEveryMessageOnceInOrder(dir, 7, 9);
  const auto json = report("report.json");
  std::map<std::string, int> fanOut;
  for (const auto& c : json["connections"]) ++fanOut[c["from"].get<std::string>()];
  EXPECT_EQ(fanOut["src.out"], 1);
  EXPECT_EQ(fanOut.size(), 4u) << "src and ceil(6/2) = 3 broadcast filters";
  for (const auto& [from, count] : fanOut) EXPECT_LE(count, 3) << from;
}

// ---- dynamic routing -----------------------------------------------------------------------

struct Received {
  std::string kind, id, op, mask, ref;
  double x = 0;
};

// tile-viewer logs: iteration,kind,id,op,mask,x,ref.
std::map<long, std::vector<Received>> byIteration(const std::string& csv) {
  std::map<long, std::vector<Received>> result;
  const auto lines = readLines(csv);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const auto f = fields(lines[i]);
    EXPECT_EQ(f.size(), 7u) << lines[i];
    if (f.size() != 7) continue;
    Received r{f[1], f[2], f[3], f[4], f[6]};
    if (!f[5].empty()) r.x = std::stod(f[5]);
    result[std::stol(f[0])].push_back(r);
  }
  return result;
}

struct Tile {
  double minX, maxX;
  bool meets(double x) const { return x - 0.5 <= maxX && x + 0.5 >= minX; }  // body size 1
};

std::string routingApp(const std::string& folder, long iterations) {
  std::string modules = moduleXml("scene", "routing/movers",
                                  paramXml("count", "48") + paramXml("dt", "0.5") +
                                      paramXml("iterations", std::to_string(iterations)) +
                                      "      <input port=\"beginIt\" initial-messages=\"1\"/>\n");
  std::string connections = connectXml("scene.objects", "wall.in");
  const char* boxes[] = {
      "0 -1 -1 10 12 1", "10 -1 -1 20 12 1", "20 -1 -1 30 12 1", "30 -1 -1 40 12 1", "all",
      "0 -1 -1 5 12 1"};
  for (int k = 0; k < 6; ++k) {
    const std::string id = "tile" + std::to_string(k);
    std::string params = paramXml("box", boxes[k]) + paramXml("file", folder + "/" + id + ".csv");
    if (k == 5) params += paramXml("box2", "30 -1 -1 35 12 1") + paramXml("move-at", "20");
    modules += moduleXml(id, "routing/tile-viewer", params);
    connections += connectXml("wall.out" + std::to_string(k), id + ".objects") +
                   connectXml(id + ".interest", "wall.interest" + std::to_string(k)) +
                   connectXml(id + ".endIt", "scene.beginIt");
  }
  return appXml(modules, filterXml("wall", "route", paramXml("outputs", "6")), connections);
}

TEST_F(Patterns, RouteForwardsExactlyTheIntersectingObjectsAndTheirStateOnEntry) {
  const long iterations = 40;
  const auto result = run(dir.write("routing.xml", routingApp(dir.path(), iterations)));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  // The viewer of everything: every body's position at every iteration (iteration 0 holds no
  // interest yet, so nothing; iteration 1 is every body's entry).
  const auto all = byIteration(dir.file("tile4.csv"));
  EXPECT_EQ(all.count(0), 0u) << "no volume published before the first message";
  std::map<long, std::map<std::string, double>> x;  // iteration -> body -> x
  for (const auto& [it, chunks] : all) {
    for (const auto& c : chunks) {
      if (c.kind == "object") x[it][c.id] = c.x;
    }
  }
  ASSERT_EQ(x.size(), static_cast<std::size_t>(iterations - 1));
  for (const auto& [it, bodies] : x) ASSERT_EQ(bodies.size(), 48u) << it;

  const auto check = [&](const std::string& csv, auto tileAt, long from, std::set<std::string> held,
                         std::set<std::string> resources) -> std::pair<long, long> {
    const auto got = byIteration(csv);
    long entries = 0, leaves = 0;
    for (long it = from; it < iterations; ++it) {
      const Tile tile = tileAt(it);
      std::set<std::string> expected;
      for (const auto& [id, px] : x[it]) {
        if (tile.meets(px) || held.count(id)) expected.insert(id);  // inside, or leaving now
      }
      std::set<std::string> objects;
      const auto found = got.find(it);
      for (const auto& c : found == got.end() ? std::vector<Received>{} : found->second) {
        if (c.kind == "resource") {
          EXPECT_TRUE(resources.insert(c.id).second) << "a static resource is sent once, " << csv;
          continue;
        }
        EXPECT_EQ(c.kind, "object");
        objects.insert(c.id);
        if (!held.count(c.id)) {
          ++entries;
          EXPECT_EQ(c.op, "add") << "state on entry: " << csv << " iteration " << it;
          EXPECT_EQ(c.mask, "ff") << "every parameter of the body";
          EXPECT_TRUE(resources.count(c.ref)) << "its mesh arrives before it";
        } else {
          EXPECT_EQ(c.op, "update");
          EXPECT_EQ(c.mask, "45") << "what the scene sends: position, velocity, bounds";
        }
        EXPECT_DOUBLE_EQ(c.x, x[it][c.id]);
      }
      EXPECT_EQ(objects, expected) << csv << " iteration " << it;
      for (const auto& id : expected) {
        if (tile.meets(x[it][id])) {
          held.insert(id);
        } else {
          held.erase(id);
          ++leaves;
        }
      }
    }
    return std::pair{entries, leaves};
  };
  for (int k = 0; k < 4; ++k) {
    const Tile tile{10.0 * k, 10.0 * k + 10};
    const auto [entries, leaves] =
        check(dir.file("tile" + std::to_string(k) + ".csv"), [&](long) { return tile; }, 1, {}, {});
    EXPECT_GT(entries, 12) << "tile " << k;
    EXPECT_GT(leaves, 3) << "bodies move across the tiles: tile " << k;
  }
  // The viewer that moves: its new volume (published at iteration 20) applies from message 21,
  // whose chunks are then the full state of every body inside it, none of the old ones.
  const auto moving = byIteration(dir.file("tile5.csv"));
  std::set<std::string> expected, added, resources;
  for (const auto& [id, px] : x[21]) {
    if (Tile{30, 35}.meets(px)) expected.insert(id);
  }
  for (long it = 1; it < 21; ++it) {
    for (const auto& c : moving.count(it) ? moving.at(it) : std::vector<Received>{}) {
      if (c.kind == "resource") resources.insert(c.id);
    }
  }
  for (const auto& c : moving.at(21)) {
    if (c.kind == "resource") {
      EXPECT_TRUE(resources.insert(c.id).second) << "a static resource is sent once";
      continue;
    }
    EXPECT_EQ(c.op, "add");
    EXPECT_EQ(c.mask, "ff");
    EXPECT_TRUE(resources.count(c.ref)) << "its mesh arrives before it";
    EXPECT_TRUE(added.insert(c.id).second) << "once";
  }
  EXPECT_FALSE(expected.empty());
  EXPECT_EQ(added, expected);
  check(
      dir.file("tile5.csv"),
      [](long) {
        return Tile{30, 35};
      },
      22, expected, resources);
}

// Meshes sent after the bodies that use them (iteration 3) reach a viewer only if it holds such
// a body; a delete reaches only the viewers that hold the body.
TEST_F(Patterns, RouteSendsLateResourcesToTheirHoldersAndDeletesWhereHeld) {
  const auto result = run(dir.write(
      "late.xml",
      moversWall(paramXml("count", "16") + paramXml("meshes", "8") + paramXml("iterations", "12") +
                     paramXml("meshes-at", "3") + paramXml("delete-at", "6"),
                 {"0 -1 -1 10 12 1", "20 -1 -1 30 12 1", "all"})));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto all = byIteration(dir.file("v2.csv"));
  std::string first;  // body 0: the first body added
  std::map<std::string, std::string> shapeOf;
  for (const auto& c : all.at(1)) {
    if (first.empty()) first = c.id;
    shapeOf[c.id] = c.ref;
  }
  ASSERT_EQ(shapeOf.size(), 16u);
  for (int k = 0; k < 3; ++k) {
    const auto got = byIteration(dir.file("v" + std::to_string(k) + ".csv"));
    std::set<std::string> refs, resources, heldAt3;
    std::map<std::string, std::string> refOf;
    bool holdsFirst = false, deleted = false;
    for (const auto& [it, chunks] : got) {
      for (const auto& c : chunks) {
        if (c.kind == "resource") {
          EXPECT_TRUE(resources.insert(c.id).second) << "once";
          EXPECT_GE(it, 3) << "no mesh before the scene sends it";
          continue;
        }
        if (c.op == "add") {
          refOf[c.id] = c.ref;
          if (it >= 3) {
            EXPECT_TRUE(resources.count(c.ref)) << "the mesh comes before the body";
          }
        }
        if (it == 3 && c.op == "update") heldAt3.insert(c.id);
        if (c.id == first && c.op != "delete") holdsFirst = true;
        if (c.id == first && c.op == "delete") {
          EXPECT_EQ(it, 6);
          deleted = true;
        } else if (c.id == first) {
          EXPECT_LT(it, 6) << "nothing about a deleted body";
        }
      }
      if (it == 3) {
        std::set<std::string> needed;
        for (const auto& id : heldAt3) needed.insert(refOf[id]);
        EXPECT_EQ(resources, needed) << "viewer " << k << ": exactly the meshes of its bodies";
      }
    }
    for (const auto& [id, ref] : refOf) refs.insert(ref);
    for (const auto& r : resources)
      EXPECT_TRUE(refs.count(r)) << "viewer " << k << ": unasked mesh";
    EXPECT_EQ(deleted, holdsFirst) << "viewer " << k;
  }
  EXPECT_EQ(byIteration(dir.file("v2.csv")).at(3).size(), 16u + 8u) << "all: 8 meshes, 16 bodies";
}

// A dynamic resource (a fluid region's particles, say) reaches a receiver only while it holds
// an object that refers to it: one body with a dynamic mesh re-sent every iteration (vertex 0's
// x = the iteration) moves along x through a volume, leaves, wraps around and comes back. The
// volume's receiver gets the mesh with every update of the body it holds, nothing between, and
// on re-entry the newest copy, before the body's entry; the receiver of everything gets every
// copy.
TEST_F(Patterns, RouteSendsDynamicResourcesOnlyWhileTheirObjectsAreInTheVolume) {
  const auto result = run(dir.write(
      "dynamic.xml", moversWall(paramXml("count", "1") + paramXml("meshes", "1") +
                                    paramXml("mesh-triangles", "4") + paramXml("width", "4") +
                                    paramXml("dt", "0.1") + paramXml("iterations", "120") +
                                    paramXml("dynamic-meshes", "true"),
                                {"0 -1 -1 1 1 1", "all"})));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto all = byIteration(dir.file("v1.csv"));
  const auto got = byIteration(dir.file("v0.csv"));
  std::map<long, double> copyAt;  // iteration -> the copy of the mesh the scene sent then
  for (const auto& [it, chunks] : all) {
    int meshes = 0;
    for (const auto& c : chunks) {
      if (c.kind == "resource") {
        copyAt[it] = c.x;
        ++meshes;
      }
    }
    EXPECT_EQ(meshes, 1) << "the receiver of everything gets every copy, iteration " << it;
  }
  ASSERT_GT(copyAt.size(), 100u);
  long entries = 0, absent = 0;
  bool held = false;
  for (long it = 1; it < 120; ++it) {
    const auto found = got.find(it);
    bool body = false, mesh = false, meshFirst = false;
    double copy = -1;
    std::string op;
    if (found != got.end()) {
      for (const auto& c : found->second) {
        if (c.kind == "resource") {
          mesh = true;
          copy = c.x;
          meshFirst = !body;
        } else if (c.kind == "object") {
          body = true;
          op = c.op;
        }
      }
    }
    const bool holds = body && op != "delete";
    if (!body) ++absent;
    if (holds && !held) {
      ++entries;
      EXPECT_EQ(op, "add") << "an entry brings the full state, iteration " << it;
      EXPECT_TRUE(meshFirst) << "the mesh comes before the body, iteration " << it;
    }
    if (holds) {
      EXPECT_TRUE(mesh) << "the newest mesh with the body it holds, iteration " << it;
      if (copyAt.count(it) != 0) {
        EXPECT_EQ(copy, copyAt[it]) << "iteration " << it;
      }
    } else {
      EXPECT_FALSE(mesh) << "no mesh for a body it does not hold, iteration " << it;
    }
    held = holds;
  }
  EXPECT_EQ(entries, 2) << "the body enters, leaves and enters again";
  EXPECT_GT(absent, 20) << "and stays away a while";
}

// core/points: a point's bounds are its position. Four points at rest at x = 0, 1, 2, 3; a
// volume over x in [-0.5, 1.5] gets points 0 and 1 only (their full state first: the add's
// mass with the latest position and velocity), every iteration.
TEST_F(Patterns, RouteJudgesPointsByTheirPosition) {
  const auto app =
      dir.write("points.xml",
                appXml(moduleXml("pts", "core/points",
                                 paramXml("count", "4") +
                                     "      <input port=\"beginIt\" initial-messages=\"1\"/>\n") +
                           moduleXml("view", "routing/tile-viewer",
                                     paramXml("box", "-0.5 -1 -1 1.5 1 1") +
                                         paramXml("file", dir.file("view.csv"))),
                       filterXml("w", "route"),
                       connectXml("pts.objects", "w.in") + connectXml("w.out0", "view.objects") +
                           connectXml("view.interest", "w.interest0") +
                           connectXml("view.endIt", "pts.beginIt")));
  const auto result = run(app, "--iterations 30");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  std::map<std::string, double> seen;
  for (const auto& [it, chunks] : byIteration(dir.file("view.csv"))) {
    for (const auto& c : chunks) {
      EXPECT_EQ(c.kind, "object");
      EXPECT_TRUE(c.x == 0.0 || c.x == 1.0) << "only the points inside, iteration " << it;
      EXPECT_EQ(c.op, seen.count(c.id) ? "update" : "add");
      EXPECT_EQ(c.mask, seen.count(c.id) ? "3" : "7") << "position, velocity (and mass)";
      seen[c.id] = c.x;
    }
  }
  EXPECT_EQ(seen.size(), 2u);
}

TEST_F(Patterns, RouteExampleCutsTheBytesToEachTile) {
  const auto result = run(example("dynamic_routing/dynamic_routing.xml"), "--report report.json");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto json = report("report.json");
  double in = 0, out = 0;
  for (const auto& c : json["connections"]) {
    if (c["from"] == "scene.objects") in = c["bytes"].get<double>();
    if (c["from"].get<std::string>().rfind("wall.out", 0) == 0) out += c["bytes"].get<double>();
  }
  ASSERT_GT(in, 0);
  EXPECT_LT(out / 4, in / 3) << "each of 4 tiles gets less than a third of the scene";
}

TEST_F(Patterns, ValidateExplainsBadPatternParameters) {
  const auto bad = dir.write(
      "bad.xml",
      appXml(moduleXml("src", "core/source") + moduleXml("rec", "core/recorder"),
             filterXml("r", "repeat", paramXml("count", "0")) +
                 filterXml("w", "route", paramXml("initially", "some")),
             connectXml("src.out", "r.in") + connectXml("r.out", "w.in") +
                 connectXml("rec.endIt", "w.interest0") + connectXml("w.out0", "rec.in")));
  const auto refused = runVrflow({"validate", bad});
  EXPECT_EQ(refused.exitCode, 1);
  EXPECT_NE(refused.err.find("bad.xml:"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("error: parameter 'count' of filter 'r' (repeat) is 0, below its "
                             "minimum 1"),
            std::string::npos)
      << refused.err;
  EXPECT_NE(refused.err.find("parameter 'initially' of filter 'w' (route) expects one of"),
            std::string::npos)
      << refused.err;
  // A receiver -> interest cycle needs no initial message: interest does not gate out.
  const auto good = dir.write(
      "good.xml", appXml(moduleXml("src", "core/source") + moduleXml("rec", "core/recorder"),
                         filterXml("w", "route"),
                         connectXml("src.out", "w.in") + connectXml("rec.endIt", "w.interest0") +
                             connectXml("w.out0", "rec.in")));
  const auto ok = runVrflow({"validate", good});
  EXPECT_EQ(ok.exitCode, 0) << ok.err;
  // A cycle through route's `in` still needs one.
  const auto cycle =
      dir.write("cycle.xml",
                appXml(moduleXml("relay", "core/relay"), filterXml("w", "route"),
                       connectXml("relay.out", "w.in") + connectXml("relay.endIt", "w.interest0") +
                           connectXml("w.out0", "relay.in")));
  const auto deadlock = runVrflow({"validate", cycle});
  EXPECT_EQ(deadlock.exitCode, 1);
  EXPECT_NE(deadlock.err.find("cycle without initial message (would deadlock): relay.out -> w.in, "
                              "w.out0 -> relay.in"),
            std::string::npos)
      << deadlock.err;
}

// ---- greedy sampling -----------------------------------------------------------------------

// A writer of 10,000 messages and a reader that takes 10 ms per message, joined by `latest`
// synced by the reader's endIt: the writer never waits for the reader (if it did, the run would
// need 100 s and hit its timeout), the reader gets increasing samples, and shared memory stays
// bounded by the buffers.
TEST_F(Patterns, GreedySamplingNeverBlocksTheWriterAndKeepsMemoryFlat) {
  const auto file = dir.write(
      "greedy.xml",
      appXml(
          moduleXml("fast", "core/source", paramXml("size", "4096") + paramXml("count", "10000")) +
              moduleXml("slow", "testing/slow", paramXml("delay-ms", "10")) +
              moduleXml("rec", "core/recorder", paramXml("file", dir.file("sampled.csv"))),
          filterXml("sample", "latest"),
          connectXml("fast.out", "sample.in") + connectXml("sample.out", "slow.in") +
              connectXml("slow.endIt", "sample.sync") + connectXml("slow.out", "rec.in")));
  const auto result =
      runVrflow({"run", file, "--report", dir.file("report.json"), "--timeout", "60"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto json = report("report.json");
  std::map<std::string, long> iterations;
  for (const auto& m : json["modules"]) iterations[m["id"]] = m["iterations"].get<long>();
  EXPECT_EQ(iterations["fast"], 10000);
  EXPECT_LT(iterations["slow"], 10000);
  EXPECT_GE(iterations["slow"], 1);
  for (const auto& c : json["connections"]) EXPECT_EQ(c["stayed_full"], false) << c["from"];
  EXPECT_LT(json["timing"]["segment_peak_bytes"].get<uint64_t>(), 1u << 20);
  const auto counters = recordedCounters(dir.file("sampled.csv"));
  ASSERT_FALSE(counters.empty());
  for (std::size_t i = 1; i < counters.size(); ++i) EXPECT_GT(counters[i], counters[i - 1]);
  EXPECT_EQ(counters.back(), 9999) << "the newest message is the last one read";
}

// ---- module duplication --------------------------------------------------------------------

TEST_F(Patterns, DuplicatedInteractorGivesTheSameFinalDigestAsOneCopy) {
  std::map<std::string, std::string> digests;
  for (const std::string name : {"one_gravity", "duplicated_gravity"}) {
    const auto result = run(example("duplicated_interactor/" + name + ".xml"),
                            "--iterations 200 --report " + name + ".json");
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const auto json = report(name + ".json");
    for (const auto& o : json["outputs"]) {
      if (o["module"] == "chain") digests[name] = o["last_digest"].get<std::string>();
    }
    if (name == "duplicated_gravity") {
      std::set<std::string> copies;
      for (const auto& m : json["modules"]) {
        const auto id = m["id"].get<std::string>();
        if (id.rfind("gravity:copy", 0) == 0) {
          copies.insert(id);
          EXPECT_EQ(m["iterations"], 200) << id;
        }
      }
      EXPECT_EQ(copies.size(), 3u);
    }
  }
  ASSERT_EQ(digests.size(), 2u);
  EXPECT_EQ(digests["one_gravity"], digests["duplicated_gravity"]);
}

}  // namespace
}  // namespace vrflow::testing
