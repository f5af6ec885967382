// Filter plugins: shared libraries loaded by `vrflow` without rebuilding it (docs/filters.md,
// "Plugins"), through the `plugin` attribute or VRFLOW_FILTER_PATH; bad ones are refused with
// a message, never a crash.
#include <gtest/gtest.h>

#include <utility>

#include "app_text.hpp"
#include "process_helpers.hpp"
#include "vrflow/daemon/plugin.hpp"

namespace vrflow::testing {
namespace {

class FilterPlugins : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  // An application decimating 10 messages through filter `every-nth` (n=3).
  std::string decimating(const std::string& pluginAttribute) {
    return dir.write(
        "app.xml",
        appXml(moduleXml("src", "core/source", paramXml("count", "10")) +
                   moduleXml("rec", "core/recorder", paramXml("file", dir.file("out.csv"))),
               filterXml("d", "every-nth", paramXml("n", "3"), pluginAttribute),
               connectXml("src.out", "d.in") + connectXml("d.out", "rec.in")));
  }
  // `vrflow ARGS` with VRFLOW_FILTER_PATH set to `filterPath`.
  CommandResult vrflowWithFilterPath(const std::string& filterPath,
                                     const std::vector<std::string>& args) {
    std::vector<std::string> argv{"/usr/bin/env", "VRFLOW_FILTER_PATH=" + filterPath,
                                  binDir() + "/vrflow", "--packages",
                                  binDir() + "/../test-packages"};
    argv.insert(argv.end(), args.begin(), args.end());
    return runCommand(argv);
  }
  static std::string examplePlugin() {
    return binDir() + "/../lib/vrflow/filters/libvrflow_every_nth.so";
  }
  static std::string testPlugin(const std::string& name) {
    return binDir() + "/../lib/test-plugins/libvrflow_testing_" + name + ".so";
  }
  TempDir dir;
};

TEST_F(FilterPlugins, PluginNamedByTheApplicationFileRunsItsFilter) {
  const auto result = runVrflow({"run", decimating("plugin=\"" + examplePlugin() + "\"")});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(recordedCounters(dir.file("out.csv")), (std::vector<long>{0, 3, 6, 9}));
}

TEST_F(FilterPlugins, PluginByNameIsFoundBesideTheProgram) {
  // <bin>/../lib/vrflow/filters is searched for a relative name not found next to the file.
  const auto result = runVrflow({"run", decimating("plugin=\"libvrflow_every_nth.so\"")});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(recordedCounters(dir.file("out.csv")), (std::vector<long>{0, 3, 6, 9}));
}

TEST_F(FilterPlugins, PluginsOnTheFilterPathAreKnownToEveryApplication) {
  const auto file = decimating("");
  const auto unknown = runVrflow({"validate", file});
  EXPECT_EQ(unknown.exitCode, 1);
  EXPECT_NE(unknown.err.find("unknown filter type 'every-nth'"), std::string::npos) << unknown.err;
  // A folder on the path stands for the plugins in it.
  const auto result =
      vrflowWithFilterPath("/nonexistent:" + binDir() + "/../lib/vrflow/filters", {"run", file});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(recordedCounters(dir.file("out.csv")), (std::vector<long>{0, 3, 6, 9}));
}

TEST_F(FilterPlugins, MissingPluginIsAnErrorAtTheAttribute) {
  const auto file = decimating("plugin=\"libnosuch.so\"");
  const auto result = runVrflow({"validate", file});
  EXPECT_EQ(result.exitCode, 1);
  // The filter element is on line 15.
  EXPECT_NE(result.err.find(file + ":15:"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("error: filter plugin 'libnosuch.so' not found"), std::string::npos)
      << result.err;
}

TEST_F(FilterPlugins, LibraryThatIsNoPluginIsRefused) {
  const auto result =
      runVrflow({"run", decimating("plugin=\"" + testPlugin("not_a_plugin") + "\"")});
  EXPECT_EQ(result.exitCode, 2);
  EXPECT_NE(result.err.find("not a vrflow filter plugin"), std::string::npos) << result.err;
}

TEST_F(FilterPlugins, PluginBuiltForAnotherAbiIsRefusedNamingTheFileAndBothVersions) {
  const std::string current = std::to_string(daemon::kFilterPluginAbi);
  // ABI 1 (vrflowFilterPluginAbi + vrflowRegisterFilters), and a later one's entry point.
  for (const auto& [name, abi] : {std::pair{"old_abi_plugin", "1"}, {"other_abi_plugin", "999"}}) {
    const std::string file = testPlugin(name);
    const auto result = runVrflow({"validate", decimating("plugin=\"" + file + "\"")});
    EXPECT_EQ(result.exitCode, 1) << name;
    EXPECT_NE(result.err.find("filter plugin '" + file + "': built for filter plugin ABI " +
                              std::string(abi) + ", this vrflow has ABI " + current +
                              " (it must export vrflowFilterPluginV" + current + ")"),
              std::string::npos)
        << result.err;
    const auto onPath = vrflowWithFilterPath(file, {"validate", decimating("")});
    EXPECT_EQ(onPath.exitCode, 2) << name;
    EXPECT_NE(onPath.err.find("built for filter plugin ABI " + std::string(abi)), std::string::npos)
        << onPath.err;
  }
}

TEST_F(FilterPlugins, PluginRedefiningABuiltinFilterIsRefused) {
  const auto onPath =
      vrflowWithFilterPath(testPlugin("clashing_plugin"), {"validate", decimating("")});
  EXPECT_EQ(onPath.exitCode, 2);
  EXPECT_NE(onPath.err.find("filter type 'merge' exists already"), std::string::npos) << onPath.err;

  const auto named =
      runVrflow({"validate", decimating("plugin=\"" + testPlugin("clashing_plugin") + "\"")});
  EXPECT_EQ(named.exitCode, 1);
  EXPECT_NE(named.err.find("filter type 'merge' exists already"), std::string::npos) << named.err;
}

// A filter reads typed parameters (FilterContext::params()): reading one that its declaration
// does not have stops the run's start with a message naming the filter and the parameter (it
// once got the fallback silently).
TEST_F(FilterPlugins, FilterReadingAnUndeclaredParameterStopsTheRunNamingIt) {
  const auto file = dir.write(
      "app.xml",
      appXml(moduleXml("src", "core/source", paramXml("count", "10")) +
                 moduleXml("rec", "core/recorder", paramXml("file", dir.file("out.csv"))),
             filterXml("d", "misread", "", "plugin=\"" + testPlugin("misreading_plugin") + "\""),
             connectXml("src.out", "d.in") + connectXml("d.out", "rec.in")));
  const auto result = runVrflow({"run", file});
  EXPECT_NE(result.exitCode, 0) << result.err;
  EXPECT_NE(result.err.find("filter 'd' (misread): reads parameter 'm', which is not declared "
                            "(declared: n)"),
            std::string::npos)
      << result.err;
}

}  // namespace
}  // namespace vrflow::testing
