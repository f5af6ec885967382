// The composite_workers example: `vrflow run` expands the composites and runs the flat network;
// the recorded positions show every chain, in the order the merge tree joins them.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <sstream>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

std::string exampleFile() {
  return sourceDir() + "/examples/composite_workers/composite_workers.xml";
}

struct Row {
  long iteration = 0;
  double x = 0, y = 0;
};

std::vector<Row> readPositions(const std::string& path) {
  std::vector<Row> rows;
  const std::vector<std::string> lines = readLines(path);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::vector<std::string> f;
    std::stringstream in(lines[i]);
    for (std::string field; std::getline(in, field, ',');) f.push_back(field);
    EXPECT_EQ(f.size(), 9u)
        << lines[i];  // iteration,source,source_iteration,sim_time,kind,id,x,y,z
    if (f.size() != 9u) continue;
    rows.push_back({std::stol(f[0]), std::stod(f[6]), std::stod(f[7])});
  }
  return rows;
}

TEST(CompositeExample, FiveChainsRunThroughTheMergeTreeAndAreAllRecorded) {
  TempDir dir;
  const std::string report = dir.file("report.json");
  const CommandResult result =
      runCommand({"/bin/sh", "-c",
                  "cd " + dir.path() + " && " + binDir() + "/vrflow run " + exampleFile() +
                      " -n 40 --no-progress --report " + report});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_TRUE(leftoverProcesses().empty());

  const auto json = nlohmann::json::parse(readFile(report));
  std::vector<std::string> modules;
  for (const auto& m : json["modules"]) modules.push_back(m["id"]);
  EXPECT_EQ(modules.size(), 16u);  // the recorder + 5 chains of points, springs, gravity
  EXPECT_NE(std::find(modules.begin(), modules.end(), "farm:c4:springs"), modules.end());

  const std::vector<Row> rows = readPositions(dir.file("out/composite_workers/positions.csv"));
  ASSERT_EQ(rows.size(), 40u * 5u * 3u);  // every iteration: 5 chains of 3 points
  // At rest, chain i has its points at x = 0, i+1, 2(i+1). The heap-shaped merge tree of five
  // leaves joins them as ((c3 c4) c0) (c1 c2): merge1 = merge2 + merge3, merge2 = merge4 + c0.
  std::vector<double> atRest;
  for (std::size_t i = 0; i < 15; ++i) {
    EXPECT_EQ(rows[i].iteration, 0);
    atRest.push_back(rows[i].x);
  }
  EXPECT_EQ(atRest, (std::vector<double>{0, 4, 8, 0, 5, 10, 0, 1, 2, 0, 2, 4, 0, 3, 6}));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].iteration, static_cast<long>(i / 15)) << "row " << i;
  }
  for (std::size_t i = rows.size() - 15; i < rows.size(); ++i) {
    EXPECT_LT(rows[i].y, 0) << "row " << i << ": gravity pulls every point down";
  }
}

TEST(CompositeExample, ExpandPrintsTheFlatNetworkThatValidates) {
  TempDir dir;
  const CommandResult expanded = runCommand({binDir() + "/vrflow", "expand", exampleFile()});
  ASSERT_EQ(expanded.exitCode, 0) << expanded.err;
  EXPECT_NE(expanded.out.find(R"(<module id="farm:c2:points" package="core" type="points">)"),
            std::string::npos);
  EXPECT_NE(expanded.out.find(R"(<connection from="farm:merge4.out" to="farm:merge2.in0"/>)"),
            std::string::npos);
  EXPECT_EQ(expanded.out.find("<instances>"), std::string::npos);
  const std::string flat = dir.write("flat.xml", expanded.out);
  const CommandResult valid = runCommand({binDir() + "/vrflow", "validate", flat});
  EXPECT_EQ(valid.exitCode, 0) << valid.err;
}

TEST(CompositeExample, ValidateReportsAProblemInACompositeWithTheInstanceLine) {
  TempDir dir;
  std::string chain = readFile(sourceDir() + "/examples/composite_workers/chain.vrc.xml");
  chain.replace(chain.find("type=\"gravity\""), 14, "type=\"gravty\"");
  dir.write("chain.vrc.xml", chain);
  dir.write("workers.vrc.xml",
            readFile(sourceDir() + "/examples/composite_workers/workers.vrc.xml"));
  const std::string app = dir.write("app.xml", readFile(exampleFile()));
  const CommandResult result = runCommand({binDir() + "/vrflow", "validate", app});
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_NE(result.err.find(dir.path() + "/chain.vrc.xml:17:"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("unknown module type 'core/gravty'"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find(dir.path() + "/workers.vrc.xml:8:7: note: in instance 'farm:c0' of "
                                         "composite 'chain'"),
            std::string::npos)
      << result.err;
  EXPECT_NE(result.err.find(app + ":9:5: note: in instance 'farm' of composite 'workers'"),
            std::string::npos)
      << result.err;
}

}  // namespace
}  // namespace vrflow::testing
