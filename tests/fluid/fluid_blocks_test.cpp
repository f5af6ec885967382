// The composite fluid_blocks (nodes/fluid/composites): the fluid as one module per MPI block.
// Its parameters against the module's manifest, its expansion through the real `vrflow expand`,
// and a job module given blocks of its own. The run itself: examples_e2e_test.cpp.
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <string>

#include "../runtime/process_helpers.hpp"

namespace vrflow::testing {
namespace {

// name -> default of every <param name=".." ... default=".."> in `xml`.
std::map<std::string, std::string> declaredParams(const std::string& xml) {
  std::map<std::string, std::string> out;
  const std::regex param(R"re(<param name="([^"]+)"[^>]*? default="([^"]*)")re");
  for (std::sregex_iterator it(xml.begin(), xml.end(), param), end; it != end; ++it) {
    out[(*it)[1].str()] = (*it)[2].str();
  }
  return out;
}

// A composite parameter that drifted from the module's default would silently change what
// fluid_blocks simulates against fluid/fluid.
TEST(FluidBlocksComposite, ForwardsEveryParameterOfTheFluidWithTheManifestsDefault) {
  const auto manifest = declaredParams(readFile(sourceDir() + "/nodes/fluid/vrflow-package.xml"));
  const std::string compositeText =
      readFile(sourceDir() + "/nodes/fluid/composites/fluid_blocks.vrc.xml");
  const auto composite = declaredParams(compositeText);
  ASSERT_GT(manifest.size(), 15u);
  for (const auto& [name, value] : manifest) {
    if (name == "blocks" || name == "job") continue;
    std::string underscored = name;
    for (char& c : underscored) c = c == '-' ? '_' : c;
    const auto found = composite.find(underscored);
    ASSERT_NE(found, composite.end()) << "fluid_blocks does not forward '" << name << "'";
    EXPECT_EQ(found->second, value) << "default of '" << name << "'";
    EXPECT_NE(compositeText.find("<param name=\"" + name + "\" value=\"${" + underscored + "}\"/>"),
              std::string::npos)
        << "the block modules do not get '" << name << "'";
  }
  EXPECT_NE(compositeText.find(R"(<param name="job" value="${instance}"/>)"), std::string::npos);
}

TEST(FluidBlocksComposite, ExpandsToOneFluidModulePerBlockInOneJob) {
  const auto result =
      runVrflow({"expand", sourceDir() + "/examples/dam_break/dam_break_blocks.xml"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const std::string& flat = result.out;
  for (const char* id : {"water:block0", "water:block1"}) {
    EXPECT_NE(flat.find(std::string("<module id=\"") + id + "\" package=\"fluid\" type=\"fluid\""),
              std::string::npos)
        << id << "\n"
        << flat;
  }
  EXPECT_EQ(flat.find("water:block2"), std::string::npos);
  // Both blocks name the instance as their job, so vrflow starts them as one mpirun.
  std::size_t jobs = 0;
  for (auto at = flat.find(R"(<param name="job" value="water"/>)"); at != std::string::npos;
       at = flat.find(R"(<param name="job" value="water"/>)", at + 1)) {
    ++jobs;
  }
  EXPECT_EQ(jobs, 2u) << flat;
  EXPECT_NE(flat.find(R"(<filter id="water:feed" type="route")"), std::string::npos) << flat;
  EXPECT_NE(flat.find(R"(from="bodies.objects" to="water:feed.in")"), std::string::npos) << flat;
  EXPECT_NE(flat.find(R"(from="water:forces.out" to="bodies.events")"), std::string::npos) << flat;
  EXPECT_NE(flat.find(R"(from="water:block1.interest" to="water:feed.interest1")"),
            std::string::npos)
      << flat;
}

TEST(FluidBlocksComposite, AModuleOfAJobWithBlocksOfItsOwnIsRefused) {
  TempDir dir;
  const auto app = dir.write("app.xml", R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="job-with-blocks" version="1">
  <modules>
    <module id="water" package="fluid" type="fluid">
      <param name="nx" value="8"/><param name="ny" value="8"/><param name="nz" value="8"/>
      <param name="cell-size" value="0.1"/><param name="fill-max" value="0.8 0.4 0.8"/>
      <param name="job" value="pool"/><param name="blocks" value="2"/>
    </module>
  </modules>
</application>
)");
  const auto result = runVrflow({"run", app, "-n", "5", "--timeout", "60", "--no-progress"}, 90);
  EXPECT_NE(result.exitCode, 0);
  EXPECT_NE(result.err.find("water"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("job"), std::string::npos) << result.err;
  for (const auto& line : leftoverProcesses()) {
    EXPECT_NE(line.find("(reaped)"), std::string::npos) << "still running: " << line;
  }
}

}  // namespace
}  // namespace vrflow::testing
