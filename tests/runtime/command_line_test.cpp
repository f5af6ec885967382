// The `vrflow` command line: options, output files checked before a run, and how many lines of
// diagnostics a bad file prints. Each test runs the real `vrflow`.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <sstream>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

// A source feeding a recorder that writes `csv`: the file exists only if the run started.
std::string recorderApp(const std::string& csv) {
  return "<application name=\"t\" version=\"1\">\n"
         "  <modules>\n"
         "    <module id=\"src\" package=\"core\" type=\"source\"/>\n"
         "    <module id=\"rec\" package=\"core\" type=\"recorder\">\n"
         "      <param name=\"file\" value=\"" +
         csv +
         "\"/>\n"
         "    </module>\n"
         "  </modules>\n"
         "  <connections>\n"
         "    <connection from=\"src.out\" to=\"rec.in\"/>\n"
         "  </connections>\n"
         "</application>\n";
}

// A composite whose `section` repeats `body` `count` times, and one instance of it.
std::string repeatApp(const std::string& count, const std::string& body,
                      const std::string& section = "filters") {
  return "<application name=\"t\" version=\"1\">\n"
         "  <composites>\n"
         "    <composite name=\"c\">\n"
         "      <" +
         section +
         ">\n"
         "        <repeat var=\"i\" count=\"" +
         count + "\">\n          " + body +
         "\n        </repeat>\n"
         "      </" +
         section +
         ">\n"
         "    </composite>\n"
         "  </composites>\n"
         "  <instances>\n"
         "    <instance id=\"w\" composite=\"c\"/>\n"
         "  </instances>\n"
         "</application>\n";
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> result;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) result.push_back(line);
  return result;
}

double secondsSince(std::chrono::steady_clock::time_point begin) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
}

class CommandLineTest : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  TempDir dir;
};

// Item 9: a run used to do all its work, then fail with "cannot write the report".
TEST_F(CommandLineTest, ReportOrTracePathThatCannotBeWrittenIsRefusedBeforeAnythingStarts) {
  const std::string csv = dir.file("out.csv");
  const std::string file = dir.write("app.xml", recorderApp(csv));
  std::filesystem::create_directory(dir.file("folder"));
  struct Case {
    std::vector<std::string> args;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {{"--report", dir.file("missing/r.json")},
       "cannot write the report to '" + dir.file("missing/r.json") + "': folder '" +
           dir.file("missing") + "' does not exist"},
      {{"--trace", dir.file("folder")},
       "cannot write the trace to '" + dir.file("folder") + "': it is a folder"},
      {{"--report", dir.file("ok.json"), "--trace", dir.file("out.csv/t.json")},
       "cannot write the trace to '" + dir.file("out.csv/t.json") + "': folder '" +
           dir.file("out.csv") + "' does not exist"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args{"run", file, "-n", "100000", "--no-progress"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const auto begin = std::chrono::steady_clock::now();
    const auto result = runVrflow(args);
    EXPECT_EQ(result.exitCode, 2) << result.err;
    EXPECT_EQ(lines(result.err), std::vector<std::string>{"vrflow: " + c.expected});
    EXPECT_FALSE(std::filesystem::exists(csv)) << "the run started";
    EXPECT_FALSE(std::filesystem::exists(dir.file("ok.json")));
    EXPECT_LT(secondsSince(begin), 10.0);
  }
  if (geteuid() != 0) {  // root writes anywhere
    std::filesystem::create_directory(dir.file("readonly"));
    chmod(dir.file("readonly").c_str(), 0500);
    const auto result =
        runVrflow({"run", file, "-n", "10", "--report", dir.file("readonly/r.json")});
    EXPECT_EQ(result.exitCode, 2);
    EXPECT_NE(result.err.find("folder '" + dir.file("readonly") + "' is not writable"),
              std::string::npos)
        << result.err;
    EXPECT_FALSE(std::filesystem::exists(csv));
    chmod(dir.file("readonly").c_str(), 0700);
  }
}

// Item 11: problems sharing one source location were deduplicated pairwise (a 256-input merge
// repeated took 14.9 s to validate) and every one was printed.
TEST_F(CommandLineTest, ValidatePrintsAScreenfulOfProblemsThenHowManyMore) {
  // 20,000 relays without input: 20,000 problems at one place (the cap is 100,000 items,
  // repeat iterations included).
  const std::string file = dir.write(
      "app.xml",
      repeatApp("20000", "<module id=\"r${i}\" package=\"core\" type=\"relay\"/>", "modules"));
  const auto begin = std::chrono::steady_clock::now();
  const auto result = runVrflow({"validate", file}, 120);
  const double seconds = secondsSince(begin);
  EXPECT_EQ(result.exitCode, 1);
  const std::vector<std::string> printed = lines(result.err);
  // 20 problems, each with its "in instance" note, then the count of the others.
  ASSERT_EQ(printed.size(), 41u) << result.err.substr(0, 2000);
  EXPECT_NE(printed[0].find("required input 'in' of module 'w:r0' (core/relay) is not connected"),
            std::string::npos)
      << printed[0];
  EXPECT_EQ(printed.back(), "... and 19980 more problems");
  EXPECT_LT(seconds, 10.0) << "a hang guard";
}

// Item 11: `count="1000000000000"` took 22 s and printed 100,002 lines.
TEST_F(CommandLineTest, HugeRepeatCountIsOneErrorInsteadOfAHundredThousandLines) {
  const std::string file =
      dir.write("app.xml", repeatApp("1000000000000", "<filter id=\"m${i}\" type=\"merge\"/>"));
  const auto begin = std::chrono::steady_clock::now();
  const auto result = runVrflow({"validate", file}, 120);
  EXPECT_EQ(result.exitCode, 1);
  const std::vector<std::string> printed = lines(result.err);
  ASSERT_EQ(printed.size(), 2u) << result.err.substr(0, 2000);
  EXPECT_NE(printed[0].find(file + ":5:9: error: the expansion makes more than 100000"),
            std::string::npos)
      << printed[0];
  EXPECT_NE(printed[1].find("note: in instance 'w' of composite 'c'"), std::string::npos);
  EXPECT_LT(secondsSince(begin), 10.0) << "a hang guard: it took 22 s before";
}

// Item 11: nested 1000 x 1000 x 1000 repeats ran past 15 s.
TEST_F(CommandLineTest, NestedRepeatsAreRefusedByTheProductOfTheirCounts) {
  const std::string file =
      dir.write("app.xml", repeatApp("1000",
                                     "<repeat var=\"j\" count=\"1000\"><repeat var=\"k\" "
                                     "count=\"1000\"><filter id=\"m${i}_${j}_${k}\" "
                                     "type=\"merge\"/></repeat></repeat>"));
  const auto begin = std::chrono::steady_clock::now();
  const auto result = runVrflow({"validate", file}, 120);
  EXPECT_EQ(result.exitCode, 1);
  const std::vector<std::string> printed = lines(result.err);
  ASSERT_EQ(printed.size(), 2u) << result.err.substr(0, 2000);
  EXPECT_NE(printed[0].find("repeat count 1000 times the counts of the repeats around it"),
            std::string::npos)
      << printed[0];
  EXPECT_LT(secondsSince(begin), 10.0) << "a hang guard";
}

// Item 12: `--deadlock-timeout 0` printed the range up to DBL_MAX in full.
TEST_F(CommandLineTest, ZeroDeadlockTimeoutIsRefusedInOneShortLine) {
  const auto result = runVrflow(
      {"run", dir.write("app.xml", recorderApp(dir.file("o.csv"))), "--deadlock-timeout", "0"});
  EXPECT_EQ(result.exitCode, 2);
  EXPECT_NE(result.err.find("--deadlock-timeout: must be more than 0 seconds, got '0'"),
            std::string::npos)
      << result.err;
  EXPECT_EQ(result.err.find("179769"), std::string::npos) << result.err;
  EXPECT_LT(result.err.size(), 300u) << result.err;
}

// Item 12: `-n abc` said "not in range".
TEST_F(CommandLineTest, IterationCountThatIsNotANumberIsCalledSo) {
  const std::string file = dir.write("app.xml", recorderApp(dir.file("o.csv")));
  const auto result = runVrflow({"run", file, "-n", "abc"});
  EXPECT_EQ(result.exitCode, 2);
  EXPECT_NE(result.err.find("'abc' is not a number"), std::string::npos) << result.err;
  EXPECT_EQ(result.err.find("range"), std::string::npos) << result.err;
  const auto negative = runVrflow({"run", file, "-n", "-3"});
  EXPECT_EQ(negative.exitCode, 2);
  EXPECT_NE(negative.err.find("'-3' is not a number"), std::string::npos) << negative.err;
}

// Item 12: `--timeout 0` silently meant "no timeout"; leaving the option out means that.
TEST_F(CommandLineTest, ZeroTimeoutIsRefusedAndSaysHowToRunWithoutALimit) {
  const std::string file = dir.write("app.xml", recorderApp(dir.file("o.csv")));
  const auto result = runVrflow({"run", file, "--timeout", "0"});
  EXPECT_EQ(result.exitCode, 2);
  EXPECT_NE(result.err.find("--timeout: must be more than 0 seconds, got '0' (leave --timeout out "
                            "to run without a time limit)"),
            std::string::npos)
      << result.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("o.csv")));
  const auto help = runVrflow({"run", "--help"});
  EXPECT_NE(help.out.find("without it, no limit"), std::string::npos) << help.out;
}

// Item 12: `validate --packages DIR APP.xml` and `run APP.xml --bogus` both said "APP.xml is
// required".
TEST_F(CommandLineTest, CommonOptionsAreAcceptedAfterTheSubcommandAndListedInItsHelp) {
  const std::string file = dir.write("app.xml", recorderApp(dir.file("o.csv")));
  const std::string packages = binDir() + "/../test-packages";
  const auto validate =
      runCommand({binDir() + "/vrflow", "validate", "--packages", packages, file});
  EXPECT_EQ(validate.exitCode, 0) << validate.err;
  const auto twice = runCommand({binDir() + "/vrflow", "validate", "--packages", packages,
                                 "--packages", packages, "--set", "rec.file=x.csv", file});
  EXPECT_EQ(twice.exitCode, 0) << twice.err;
  const auto bogus = runVrflow({"run", file, "--bogus"});
  EXPECT_EQ(bogus.exitCode, 2);
  EXPECT_NE(bogus.err.find("--bogus"), std::string::npos) << bogus.err;
  EXPECT_EQ(bogus.err.find("is required"), std::string::npos) << bogus.err;
  for (const char* command : {"validate", "expand", "run"}) {
    const auto help = runCommand({binDir() + "/vrflow", command, "--help"});
    EXPECT_EQ(help.exitCode, 0);
    for (const char* option : {"--packages", "--composites", "--set"}) {
      EXPECT_NE(help.out.find(option), std::string::npos) << command << " --help lacks " << option;
    }
  }
}

}  // namespace
}  // namespace vrflow::testing
