// Every example runs, and does what its README says.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  for (std::string field; std::getline(in, field, ',');) fields.push_back(field);
  return fields;
}

TEST(Examples, PipelineDemoIsDeterministicAndRecordsEveryIteration) {
  TempDir dir;
  std::string digests[2];
  for (int run = 0; run < 2; ++run) {
    const auto report = dir.file("report" + std::to_string(run) + ".json");
    const auto result =
        runCommand({"/bin/sh", "-c",
                    "cd " + dir.path() + " && " + binDir() + "/vrflow run " + sourceDir() +
                        "/examples/pipeline/pipeline.xml -n 50 --report " + report});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const auto json = nlohmann::json::parse(readFile(report));
    for (const auto& o : json["outputs"]) digests[run] += o["last_digest"].dump();
  }
  EXPECT_EQ(digests[0], digests[1]);
  const auto lines = readLines(dir.file("out/demo/trajectory.csv"));
  EXPECT_EQ(lines.size(), 1u + 50u * 8u);  // header + 8 points per iteration
  EXPECT_TRUE(leftoverProcesses().empty());
}

// An output file parameter stays relative to the run's working folder even when a file of that
// name lies beside the application (an earlier run's output there must not draw this run's).
TEST(Examples, AnOutputBesideTheApplicationDoesNotDrawTheRunsOutputThere) {
  TempDir app, work;
  const std::string file =
      app.write("pipeline.xml", readFile(sourceDir() + "/examples/pipeline/pipeline.xml"));
  std::filesystem::create_directories(app.file("out/demo"));
  const std::string stale = app.write("out/demo/trajectory.csv", "stale\n");
  const auto result =
      runCommand({"/bin/sh", "-c",
                  "cd " + work.path() + " && " + binDir() + "/vrflow run " + file + " -n 20"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(readFile(stale), "stale\n");
  EXPECT_EQ(readLines(work.file("out/demo/trajectory.csv")).size(), 1u + 20u * 8u);
  EXPECT_TRUE(leftoverProcesses().empty());
}

// The README's module, coupled with core/points: x(t) = x0 cos(sqrt(k/m) t).
TEST(Examples, MinimalModuleOscillatesWithTheSpringPeriod) {
  TempDir dir;
  const auto result =
      runCommand({"/bin/sh", "-c",
                  "cd " + dir.path() + " && " + binDir() + "/vrflow run " + sourceDir() +
                      "/examples/minimal_module/oscillator.xml -n 1000 --packages " + binDir() +
                      "/../share/vrflow/example-packages"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto lines = readLines(dir.file("oscillator.csv"));
  ASSERT_EQ(lines.size(), 1u + 1000u * 3u);
  double worst = 0;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const auto f = split(lines[i]);  // iteration,source,source_iteration,sim_time,kind,id,x,y,z
    ASSERT_GE(f.size(), 9u) << lines[i];
    const double t = std::stod(f[3]);
    const double x = std::stod(f[6]);
    const double x0 = static_cast<double>((i - 1) % 3);  // points start at x = 0, 1, 2
    worst = std::max(worst, std::abs(x - x0 * std::cos(2.0 * t)));
  }
  EXPECT_LT(worst, 5e-3);  // semi-implicit Euler at dt = 1 ms over one period
  EXPECT_TRUE(leftoverProcesses().empty());
}

// The README's plugin: a filter type added by a shared library that the file names.
TEST(Examples, FilterPluginKeepsOneMessageInN) {
  TempDir dir;
  const auto result = runCommand({"/bin/sh", "-c",
                                  "cd " + dir.path() + " && " + binDir() + "/vrflow run " +
                                      sourceDir() + "/examples/filter_plugin/every_nth.xml"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto lines = readLines(dir.file("every_nth.csv"));
  ASSERT_EQ(lines.size(), 1u + 4u);  // header + messages 0, 5, 10, 15 of 20
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const auto f = split(lines[i]);  // iteration,source,source_iteration,sim_time,kind,id,counter
    ASSERT_GE(f.size(), 7u) << lines[i];
    EXPECT_EQ(f[6], std::to_string(5 * (i - 1))) << lines[i];
  }
  EXPECT_TRUE(leftoverProcesses().empty());
}

}  // namespace
}  // namespace vrflow::testing
