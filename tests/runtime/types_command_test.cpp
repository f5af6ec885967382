// `vrflow types` (issue 19, item 6): the installed module and filter types with their ports and
// parameters, from the same search path as `vrflow run`.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(TypesCommand, ListsEveryModuleTypeAndEveryBuiltInFilterTypeOneALine) {
  const auto result = runVrflow({"types"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_TRUE(contains(result.out, "\n  core/relay ")) << result.out;
  EXPECT_TRUE(contains(result.out, "\n  core/recorder ")) << result.out;
  EXPECT_TRUE(contains(result.out, "\n  testing/crash ")) << "--packages is honoured";
  EXPECT_TRUE(contains(result.out, "\n  merge ")) << result.out;
  EXPECT_TRUE(contains(result.out, "built-in")) << result.out;
}

TEST(TypesCommand, ShowsAPackagesTypesWithTheirPortsAndParameters) {
  const auto result = runVrflow({"types", "core"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_TRUE(contains(result.out, "core/relay (module, other)")) << result.out;
  EXPECT_TRUE(contains(result.out, "  inputs:\n    in ")) << result.out;
  // A parameter with its type, default, range and doc, as the manifest declares it.
  EXPECT_TRUE(contains(result.out, "    delay-ms         int     default 0          [0, 60000]"))
      << result.out;
  EXPECT_FALSE(contains(result.out, "beginIt")) << "every module's implicit ports are not listed";
  EXPECT_FALSE(contains(result.out, "(filter, ")) << result.out;
}

TEST(TypesCommand, JsonOfOneTypeHasEveryDetailOfItsPortsAndParameters) {
  const auto result = runVrflow({"types", "core/source", "--json"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto j = nlohmann::json::parse(result.out);
  ASSERT_EQ(j["modules"].size(), 1u);
  EXPECT_TRUE(j["filters"].empty());
  const auto& source = j["modules"][0];
  EXPECT_EQ(source["package"], "core");
  EXPECT_EQ(source["type"], "source");
  EXPECT_EQ(source["executable"], binDir() + "/vrflow-core-source");
  bool sawSize = false;
  for (const auto& p : source["parameters"]) {
    if (p["name"] != "size") continue;
    sawSize = true;
    EXPECT_EQ(p["type"], "int");
    EXPECT_EQ(p["default"], "64");
    EXPECT_EQ(p["min"], 8);
    EXPECT_EQ(p["max"], 1073741824);
    EXPECT_EQ(p["doc"], "Payload bytes");
  }
  EXPECT_TRUE(sawSize) << source;
  ASSERT_FALSE(source["ports"].empty());
  EXPECT_EQ(source["ports"][0]["direction"], "output");
}

TEST(TypesCommand, ShowsANodePackage) {
  if (!std::filesystem::exists(binDir() + "/../share/vrflow/packages/massspring")) {
    GTEST_SKIP() << "the node packages are not built (VRFLOW_NODES=OFF)";
  }
  const auto result = runVrflow({"types", "massspring", "--json"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto j = nlohmann::json::parse(result.out);
  ASSERT_GE(j["modules"].size(), 2u);
  for (const auto& m : j["modules"]) {
    EXPECT_EQ(m["package"], "massspring");
    EXPECT_FALSE(m["ports"].empty()) << m;
  }
}

TEST(TypesCommand, ShowsAFilterTypeBuiltInAndOneFromAPlugin) {
  const auto merge = runVrflow({"types", "merge"});
  ASSERT_EQ(merge.exitCode, 0) << merge.err;
  EXPECT_TRUE(contains(merge.out, "merge (filter, built-in)")) << merge.out;
  EXPECT_TRUE(contains(merge.out, "    in0 ")) << merge.out;  // with the default `inputs`
  EXPECT_TRUE(contains(merge.out, "    inputs ")) << merge.out;

  const std::string plugin = binDir() + "/../lib/vrflow/filters/libvrflow_every_nth.so";
  ASSERT_TRUE(std::filesystem::exists(plugin)) << plugin;
  setenv("VRFLOW_FILTER_PATH", plugin.c_str(), 1);
  const auto listed = runVrflow({"types"});
  const auto shown = runVrflow({"types", "every-nth", "--json"});
  unsetenv("VRFLOW_FILTER_PATH");
  ASSERT_EQ(listed.exitCode, 0) << listed.err;
  EXPECT_TRUE(contains(listed.out, "\n  every-nth                      plugin ")) << listed.out;
  ASSERT_EQ(shown.exitCode, 0) << shown.err;
  const auto j = nlohmann::json::parse(shown.out);
  ASSERT_EQ(j["filters"].size(), 1u);
  EXPECT_EQ(j["filters"][0]["origin"], "plugin");
  EXPECT_FALSE(j["filters"][0]["parameters"].empty());
}

TEST(TypesCommand, AnUnknownNameIsOneMessageWithASuggestion) {
  for (const auto& [name, suggestion] : std::vector<std::pair<std::string, std::string>>{
           {"cor", "core"}, {"core/rely", "core/relay"}, {"merg", "merge"}}) {
    const auto result = runVrflow({"types", name});
    EXPECT_EQ(result.exitCode, 2) << name;
    EXPECT_TRUE(result.out.empty()) << result.out;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_TRUE(contains(result.err, "vrflow: no package, module type or filter type '" + name +
                                         "'; did you mean '" + suggestion + "'?"))
        << result.err;
  }
}

}  // namespace
}  // namespace vrflow::testing
