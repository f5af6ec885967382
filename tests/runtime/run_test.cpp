// End-to-end tests of `vrflow run`: real processes, real shared memory, real signals.
#include <gtest/gtest.h>
#include <signal.h>

#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

std::string app(const std::string& modules, const std::string& connections,
                const std::string& filters = "") {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"test\" version=\"1\">\n"
         "  <hosts>\n    <host id=\"h1\" address=\"127.0.0.1\"/>\n  </hosts>\n"
         "  <modules>\n" +
         modules + "  </modules>\n" +
         (filters.empty() ? "" : "  <filters>\n" + filters + "  </filters>\n") +
         "  <connections>\n" + connections + "  </connections>\n</application>\n";
}

std::string module(const std::string& id, const std::string& type, const std::string& inner = "") {
  const auto slash = type.find('/');
  return "    <module id=\"" + id + "\" package=\"" + type.substr(0, slash) + "\" type=\"" +
         type.substr(slash + 1) + "\" host=\"h1\"" +
         (inner.empty() ? "/>\n" : ">\n" + inner + "    </module>\n");
}

std::string param(const std::string& name, const std::string& value) {
  return "      <param name=\"" + name + "\" value=\"" + value + "\"/>\n";
}

std::string initial(const std::string& port, int count) {
  return "      <input port=\"" + port + "\" initial-messages=\"" + std::to_string(count) +
         "\"/>\n";
}

std::string connect(const std::string& from, const std::string& to) {
  return "    <connection from=\"" + from + "\" to=\"" + to + "\"/>\n";
}

nlohmann::json readJson(const std::string& path) {
  return nlohmann::json::parse(readFile(path));
}

class RunTest : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  TempDir dir;
};

TEST_F(RunTest, PipelineOfThreeModulesDeliversEveryMessageInOrder) {
  const auto csv = dir.file("out.csv");
  const auto file =
      dir.write("app.xml", app(module("src", "core/source", param("size", "4096")) +
                                   module("mid", "core/relay") +
                                   module("rec", "core/recorder", param("file", csv)),
                               connect("src.out", "mid.in") + connect("mid.out", "rec.in")));
  const auto report = dir.file("report.json");
  const auto result = runVrflow({"run", file, "--iterations", "50", "--report", report});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto lines = readLines(csv);
  ASSERT_EQ(lines.size(), 51u);
  for (int i = 0; i < 50; ++i) {
    // iteration,source,source_iteration,sim_time,kind,id,counter,size
    EXPECT_NE(lines[i + 1].find(",src," + std::to_string(i) + ","), std::string::npos)
        << lines[i + 1];
    EXPECT_NE(lines[i + 1].find("resource,"), std::string::npos);
    EXPECT_NE(lines[i + 1].find("," + std::to_string(i) + ",4096,"), std::string::npos)
        << lines[i + 1];
  }
  const auto json = readJson(report);
  EXPECT_EQ(json["status"], "ok");
  for (const auto& m : json["modules"]) EXPECT_EQ(m["iterations"], 50) << m;
  ASSERT_EQ(json["connections"].size(), 2u);
  EXPECT_EQ(json["connections"][0]["messages"], 50);
  EXPECT_GT(json["connections"][0]["bytes"].get<uint64_t>(), 50u * 4096u);
}

TEST_F(RunTest, SetOverridesAParameterOfTheFileForThisRunOnly) {
  const auto csv = dir.file("out.csv");
  const auto file = dir.write("app.xml", app(module("src", "core/source", param("size", "4096")) +
                                                 module("rec", "core/recorder", param("file", csv)),
                                             connect("src.out", "rec.in")));
  const auto result = runVrflow({"run", file, "-n", "5", "--no-progress", "--set", "src.size=128"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto lines = readLines(csv);
  ASSERT_EQ(lines.size(), 6u);
  for (int i = 1; i <= 5; ++i) {
    EXPECT_NE(lines[i].find(",128,"), std::string::npos) << lines[i];
    EXPECT_EQ(lines[i].find(",4096,"), std::string::npos) << lines[i];
  }
  // The file itself is unchanged: `vrflow expand` prints what the run used.
  EXPECT_NE(readFile(file).find("value=\"4096\""), std::string::npos);
  const auto expanded = runVrflow({"expand", file, "--set", "src.size=128"});
  ASSERT_EQ(expanded.exitCode, 0) << expanded.err;
  EXPECT_NE(expanded.out.find("<param name=\"size\" value=\"128\"/>"), std::string::npos)
      << expanded.out;
}

TEST_F(RunTest, SetWithABadValueAnUnknownModuleOrNoDotIsAClearError) {
  const auto file =
      dir.write("app.xml", app(module("src", "core/source") + module("rec", "core/recorder"),
                               connect("src.out", "rec.in")));
  const auto bad = runVrflow({"run", file, "-n", "5", "--set", "src.size=big"});
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_NE(bad.err.find("--set src.size=big: error: parameter 'size' of module 'src'"),
            std::string::npos)
      << bad.err;
  const auto unknown = runVrflow({"validate", file, "--set", "sorce.size=1"});
  EXPECT_EQ(unknown.exitCode, 1);
  EXPECT_NE(unknown.err.find("no module, filter or instance 'sorce'"), std::string::npos)
      << unknown.err;
  const auto malformed = runVrflow({"run", file, "--set", "size=1"});
  EXPECT_EQ(malformed.exitCode, 2);
  EXPECT_NE(malformed.err.find("expected ID.PARAM=VALUE"), std::string::npos) << malformed.err;
}

TEST_F(RunTest, ReportDigestsAreTheSameForTwoRuns) {
  const auto file = dir.write(
      "app.xml",
      app(module("anim", "core/points", initial("events", 1) + param("count", "5")) +
              module("spring", "core/spring"),
          connect("anim.objects", "spring.objects") + connect("spring.forces", "anim.events")));
  std::string digests[2];
  for (int run = 0; run < 2; ++run) {
    const auto report = dir.file("r" + std::to_string(run) + ".json");
    const auto result = runVrflow({"run", file, "-n", "100", "--report", report});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const auto json = readJson(report);
    for (const auto& o : json["outputs"]) {
      if (o["port"] == "endIt") continue;
      ASSERT_FALSE(o["last_digest"].is_null()) << o;
      digests[run] += o["module"].get<std::string>() + "." + o["port"].get<std::string>() + "=" +
                      o["last_digest"].get<std::string>() + ";";
    }
  }
  EXPECT_FALSE(digests[0].empty());
  EXPECT_EQ(digests[0], digests[1]);
}

// The paper (section 4.2): an initial message only on the animator's input makes animator and
// interactor alternate, like a sequential loop; one on both makes them run in parallel on
// states one iteration old.
TEST_F(RunTest, CycleWithInitialMessageOnAnimatorOnlyAlternates) {
  const auto log = dir.file("order.log");
  const auto file = dir.write(
      "app.xml",
      app(module("anim", "core/points", initial("events", 1) + param("log", log)) +
              module("spring", "core/spring", param("log", log)),
          connect("anim.objects", "spring.objects") + connect("spring.forces", "anim.events")));
  const auto result = runVrflow({"run", file, "-n", "20"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  int animLines = 0;
  for (const auto& line : readLines(log)) {
    std::smatch m;
    if (std::regex_match(line, m, std::regex(R"(anim (\d+) <- (\S+)@(\d+) chunks=\d+)"))) {
      const int it = std::stoi(m[1]);
      if (it == 0) {
        EXPECT_EQ(m[2], "anim.events") << line;  // the initial message
      } else {
        EXPECT_EQ(m[2], "spring") << line;
        EXPECT_EQ(std::stoi(m[3]), it - 1) << line;  // forces from the interactor's previous step
      }
      ++animLines;
    } else if (std::regex_match(line, m, std::regex(R"(spring (\d+) <- (\S+)@(\d+) chunks=\d+)"))) {
      EXPECT_EQ(m[2], "anim") << line;
      EXPECT_EQ(m[1], m[3]) << line;  // the state of this very iteration: strictly alternating
    } else {
      ADD_FAILURE() << "unexpected line: " << line;
    }
  }
  EXPECT_EQ(animLines, 20);
}

TEST_F(RunTest, CycleWithInitialMessagesOnBothSidesRunsInParallel) {
  const auto log = dir.file("order.log");
  const auto file = dir.write(
      "app.xml",
      app(module("anim", "core/points", initial("events", 1) + param("log", log)) +
              module("spring", "core/spring", initial("objects", 1) + param("log", log)),
          connect("anim.objects", "spring.objects") + connect("spring.forces", "anim.events")));
  const auto result = runVrflow({"run", file, "-n", "20"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  int springLines = 0;
  for (const auto& line : readLines(log)) {
    std::smatch m;
    if (std::regex_match(line, m, std::regex(R"(spring (\d+) <- (\S+)@(\d+) chunks=\d+)"))) {
      const int it = std::stoi(m[1]);
      if (it == 0) {
        EXPECT_EQ(m[2], "spring.objects") << line;
      } else {
        EXPECT_EQ(m[2], "anim") << line;
        EXPECT_EQ(std::stoi(m[3]), it - 1) << line;  // one iteration old
      }
      ++springLines;
    } else if (std::regex_match(line, m, std::regex(R"(anim (\d+) <- (\S+)@(\d+) chunks=\d+)"))) {
      const int it = std::stoi(m[1]);
      if (it > 0) {
        EXPECT_EQ(std::stoi(m[3]), it - 1) << line;
      }
    }
  }
  EXPECT_EQ(springLines, 20);
}

// The default input filter merges one message of each incoming connection into one.
TEST_F(RunTest, DefaultInputFilterMergesOneMessageFromEachConnection) {
  const auto csv = dir.file("out.csv");
  const auto file =
      dir.write("app.xml", app(module("a", "core/source") + module("b", "core/source") +
                                   module("rec", "core/recorder", param("file", csv)),
                               connect("a.out", "rec.in") + connect("b.out", "rec.in")));
  const auto result = runVrflow({"run", file, "-n", "30"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto lines = readLines(csv);
  ASSERT_EQ(lines.size(), 61u);  // header + 2 chunks per iteration
  for (int i = 0; i < 30; ++i) {
    // Both chunks of iteration i carry counter i: oldest pending of each connection, in the
    // connections' file order.
    const auto& first = lines[1 + 2 * i];
    const auto& second = lines[2 + 2 * i];
    EXPECT_EQ(first.substr(0, first.find(',')), std::to_string(i));
    EXPECT_EQ(second.substr(0, second.find(',')), std::to_string(i));
    EXPECT_NE(first.find("," + std::to_string(i) + ",64,"), std::string::npos) << first;
    EXPECT_NE(second.find("," + std::to_string(i) + ",64,"), std::string::npos) << second;
  }
}

// mode="latest": the newest pending message of each connection, older ones dropped, producers
// never held back; every delivered message is newer than the previous one, until the producers
// have done their 200: the newest is then delivered again until the reader has its 200 too.
TEST_F(RunTest, LatestModeDeliversOnlyNewerMessagesAndEndsWithTheNewest) {
  const auto csv = dir.file("out.csv");
  const auto file =
      dir.write("app.xml",
                app(module("a", "core/source") + module("b", "core/source") +
                        module("rec", "core/recorder",
                               param("file", csv) + "      <input port=\"in\" mode=\"latest\"/>\n"),
                    connect("a.out", "rec.in") + connect("b.out", "rec.in")));
  const auto result = runVrflow({"run", file, "-n", "200"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto lines = readLines(csv);
  ASSERT_GE(lines.size(), 3u);
  ASSERT_EQ((lines.size() - 1) % 2, 0u);  // always one chunk of each connection
  long last[2] = {-1, -1};
  for (std::size_t i = 1; i < lines.size(); ++i) {
    // iteration,source,source_iteration,sim_time,resource,id,counter,size,
    std::vector<std::string> f;
    std::stringstream in(lines[i]);
    for (std::string x; std::getline(in, x, ',');) f.push_back(x);
    ASSERT_GE(f.size(), 8u) << lines[i];
    const long counter = std::stol(f[6]);
    const int which = static_cast<int>((i - 1) % 2);
    // Never older than what the reader had; the same again once that producer has ended.
    EXPECT_GE(counter, last[which]) << lines[i];
    last[which] = counter;
  }
  // A full connection drops what does not fit, so one producer's last messages may never reach
  // the reader; the newest of one source at least does.
  EXPECT_TRUE(last[0] == 199 || last[1] == 199) << last[0] << " " << last[1];
  EXPECT_EQ(lines.size(), 1u + 2u * 200u) << "the reader did its 200 iterations";
}

TEST_F(RunTest, MergeFilterConcatenatesItsInputsInOrder) {
  const auto csv = dir.file("out.csv");
  const auto file = dir.write(
      "app.xml",
      app(module("a", "core/source", param("size", "16")) +
              module("b", "core/source", param("size", "32")) +
              module("rec", "core/recorder", param("file", csv)),
          connect("a.out", "m.in0") + connect("b.out", "m.in1") + connect("m.out", "rec.in"),
          "    <filter id=\"m\" type=\"merge\" host=\"h1\">\n      <param name=\"inputs\" "
          "value=\"2\"/>\n    </filter>\n"));
  const auto result = runVrflow({"run", file, "-n", "10"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto lines = readLines(csv);
  ASSERT_EQ(lines.size(), 21u);
  for (int i = 0; i < 10; ++i) {
    EXPECT_NE(lines[1 + 2 * i].find(",16,"), std::string::npos) << lines[1 + 2 * i];
    EXPECT_NE(lines[2 + 2 * i].find(",32,"), std::string::npos) << lines[2 + 2 * i];
  }
}

TEST_F(RunTest, ModuleThatExitsWithAnErrorStopsTheRunAndIsNamed) {
  const auto file = dir.write(
      "app.xml", app(module("src", "core/source") +
                         module("bad", "testing/crash", param("at", "5") + param("status", "7")) +
                         module("rec", "core/recorder", param("file", dir.file("x.csv"))),
                     connect("src.out", "bad.in") + connect("bad.out", "rec.in")));
  const auto result = runVrflow({"run", file, "--report", dir.file("r.json")});
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("module 'bad' (host h1, pid "), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("exited with status 7"), std::string::npos) << result.err;
  const auto json = readJson(dir.file("r.json"));
  EXPECT_EQ(json["status"], "failed");
}

// Module::params() is typed: reading a parameter the manifest does not declare, or as another
// type, is a bug the module cannot go on with (it once got the fallback silently).
TEST_F(RunTest, ModuleReadingAnUndeclaredParameterExitsNamingTheModuleAndTheParameter) {
  const auto file =
      dir.write("app.xml", app(module("src", "core/source") + module("bad", "testing/misread"),
                               connect("src.out", "bad.in")));
  const auto result = runVrflow({"run", file, "-n", "5"});
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("module 'bad' (testing/misread): reads parameter 'not-declared', "
                            "which is not declared (declared: what)"),
            std::string::npos)
      << result.err;
  EXPECT_NE(result.err.find("exited with status 1"), std::string::npos) << result.err;
  EXPECT_EQ(result.out.find("without an error"), std::string::npos) << result.out;
}

TEST_F(RunTest, ModuleReadingAParameterAsAnotherTypeExitsNamingIt) {
  const auto file =
      dir.write("app.xml", app(module("src", "core/source") +
                                   module("bad", "testing/misread", param("what", "wrong-type")),
                               connect("src.out", "bad.in")));
  const auto result = runVrflow({"run", file, "-n", "5"});
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("module 'bad' (testing/misread): reads parameter 'what' as a float, "
                            "but it is declared enum"),
            std::string::npos)
      << result.err;
}

TEST_F(RunTest, ModuleKilledBySignalIsReportedWithTheSignal) {
  const auto file = dir.write(
      "app.xml", app(module("src", "core/source") +
                         module("bad", "testing/crash", param("at", "2") + param("signal", "9")),
                     connect("src.out", "bad.in")));
  const auto result = runVrflow({"run", file});
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("module 'bad'"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("killed by signal 9 (Killed)"), std::string::npos) << result.err;
}

TEST_F(RunTest, SigtermStopsEveryProcess) {
  const auto file =
      dir.write("app.xml", app(module("src", "core/source") + module("mid", "core/relay") +
                                   module("rec", "core/recorder", param("file", dir.file("x.csv"))),
                               connect("src.out", "mid.in") + connect("mid.out", "rec.in")));
  const auto result = runVrflow({"run", file}, 30, 1.0, SIGTERM);
  EXPECT_EQ(result.exitCode, 130) << result.err;
  EXPECT_NE(result.err.find("interrupted by SIGTERM"), std::string::npos) << result.err;
}

TEST_F(RunTest, SigintStopsEveryProcess) {
  const auto file = dir.write(
      "app.xml",
      app(module("anim", "core/points", initial("events", 1)) + module("g", "core/gravity"),
          connect("anim.objects", "g.objects") + connect("g.forces", "anim.events")));
  const auto result = runVrflow({"run", file}, 30, 1.0, SIGINT);
  EXPECT_EQ(result.exitCode, 130) << result.err;
}

TEST_F(RunTest, RuntimeDeadlockIsReportedWithWhoWaitsOnWhat) {
  const auto file = dir.write(
      "app.xml",
      app(module("anim", "core/points", initial("events", 1)) + module("m", "testing/mute"),
          connect("anim.objects", "m.in") + connect("m.out", "anim.events")));
  const auto result = runVrflow({"run", file, "--deadlock-timeout", "1"});
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("deadlock"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("module 'anim' waits on input 'events' (from m.out)"),
            std::string::npos)
      << result.err;
  EXPECT_NE(result.err.find("module 'm' waits on input 'in' (from anim.objects)"),
            std::string::npos)
      << result.err;
}

TEST_F(RunTest, TimeoutBoundsARun) {
  const auto file =
      dir.write("app.xml", app(module("src", "core/source") + module("mid", "core/relay"),
                               connect("src.out", "mid.in")));
  const auto result = runVrflow({"run", file, "--timeout", "1"});
  EXPECT_EQ(result.exitCode, 3) << result.err;
  EXPECT_NE(result.err.find("timed out after 1 s"), std::string::npos) << result.err;
}

TEST_F(RunTest, UnconnectedOutputDropsMessagesWithoutBlockingTheModule) {
  const auto file = dir.write("app.xml", app(module("src", "core/source"), ""));
  const auto result = runVrflow({"run", file, "-n", "100", "--report", dir.file("r.json")});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(readJson(dir.file("r.json"))["modules"][0]["iterations"], 100);
}

TEST_F(RunTest, InputWithOnlyInitialMessagesGetsExactlyThoseThenEnds) {
  const auto log = dir.file("log");
  const auto file = dir.write(
      "app.xml", app(module("p", "core/points", initial("events", 2) + param("log", log)), ""));
  const auto result = runVrflow({"run", file, "--timeout", "20"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto lines = readLines(log);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "p 0 <- p.events@0 chunks=0");
  EXPECT_EQ(lines[1], "p 1 <- p.events@1 chunks=0");
  // Asked for 10 iterations, it can do only 2: the run says so (docs/module-api.md).
  const auto asked = runVrflow({"run", file, "-n", "10"});
  EXPECT_EQ(asked.exitCode, 1);
  EXPECT_NE(asked.err.find("module 'p' did 2 of 10 iterations (end of input)"), std::string::npos)
      << asked.err;
}

TEST_F(RunTest, ProgramThatNeverJoinsTheRunFailsIt) {
  const auto file = dir.write("app.xml", app(module("x", "testing/nojoin"), ""));
  const auto result = runVrflow({"run", file, "-n", "5"});
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("module 'x'"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("never called Module::init()"), std::string::npos) << result.err;
}

TEST_F(RunTest, ExhaustedSharedMemoryFailsTheRunWithAClearMessage) {
  const auto file = dir.write(
      "app.xml",
      app(module("src", "core/source", param("size", "4000000")) + module("r", "core/relay"),
          connect("src.out", "r.in")));
  const auto result = runVrflow({"run", file, "-n", "10", "--shm-size", "2"});
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("module 'src': shared memory exhausted"), std::string::npos)
      << result.err;
}

TEST_F(RunTest, InvalidApplicationIsRefusedBeforeStartingAnything) {
  const auto file = dir.write("app.xml", app(module("x", "core/nosuch"), ""));
  const auto result = runVrflow({"run", file});
  EXPECT_EQ(result.exitCode, 2);
  EXPECT_NE(result.err.find(file + ":7:"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("unknown module type"), std::string::npos) << result.err;
}

TEST_F(RunTest, ValidateReportsEachProblemAsFileLineColumn) {
  const auto file = dir.write(
      "app.xml", app(module("a", "core/points") + module("b", "core/spring"),
                     connect("a.objects", "b.objects") + connect("b.forces", "a.events")));
  const auto result = runVrflow({"validate", file});
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_TRUE(std::regex_search(
      result.err, std::regex(file + R"(:\d+:\d+: error: cycle without initial message)")))
      << result.err;
  const auto good = dir.write(
      "good.xml", app(module("a", "core/points", initial("events", 1)) + module("b", "core/spring"),
                      connect("a.objects", "b.objects") + connect("b.forces", "a.events")));
  const auto ok = runVrflow({"validate", good});
  EXPECT_EQ(ok.exitCode, 0) << ok.err;
}

TEST_F(RunTest, BadCommandLineExitsWithUsageError) {
  EXPECT_EQ(runVrflow({"run"}).exitCode, 2);
  EXPECT_EQ(runVrflow({"frobnicate"}).exitCode, 2);
  EXPECT_EQ(runVrflow({"run", "/nonexistent.xml"}).exitCode, 2);
  EXPECT_EQ(runVrflow({"run", dir.write("a.xml", "<application"), "--iterations", "x"}).exitCode,
            2);
}

TEST_F(RunTest, ModuleStartedByHandExplainsHowToStartIt) {
  const auto result = runCommand({binDir() + "/vrflow-core-relay"});
  EXPECT_EQ(result.exitCode, 2);
  EXPECT_NE(result.err.find("vrflow run"), std::string::npos) << result.err;
}

}  // namespace
}  // namespace vrflow::testing
