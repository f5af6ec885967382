#include "vrflow/app/overrides.hpp"

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vrflow/app/expand.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/validate.hpp"

namespace vrflow::app {
namespace {

constexpr std::string_view kApp = R"(<application name="x" version="1">
  <hosts><host id="h" address="127.0.0.1"/></hosts>
  <modules>
    <module id="src" package="core" type="source" host="h">
      <param name="count" value="3"/>
    </module>
    <module id="out" package="core" type="sink" host="h"/>
  </modules>
  <filters>
    <filter id="slow" type="decimate" host="h"><param name="count" value="2"/></filter>
  </filters>
  <connections>
    <connection from="src.out" to="slow.in"/>
    <connection from="slow.out" to="out.in"/>
  </connections>
</application>
)";

Application load() {
  auto app = loadApplicationString(kApp, "app.xml", nullptr);
  EXPECT_TRUE(app.ok()) << (app.ok() ? "" : app.error().message);
  return app.ok() ? std::move(*app) : Application{};
}

TEST(Overrides, ReplaceAFileParameterAndAddOneTheFileLeavesOut) {
  auto app = load();
  ASSERT_TRUE(applyOverrides(app, {"src.count=7", "src.mode=slow", "slow.count=4"}).ok());
  EXPECT_EQ(paramString(app.modules[0].params, "count", ""), "7");
  EXPECT_EQ(paramString(app.modules[0].params, "mode", ""), "slow");
  EXPECT_EQ(app.modules[0].params.size(), 2u) << "count replaced, not set twice";
  EXPECT_EQ(paramString(app.filters[0].params, "count", ""), "4");
  EXPECT_TRUE(validate(app, testing::testCatalog()).empty());
}

TEST(Overrides, LaterSettingsWinAndValuesKeepTheirEqualsSignsAndSpaces) {
  auto app = load();
  ASSERT_TRUE(applyOverrides(app, {"src.label=a=b c", "src.count=1", "src.count=2"}).ok());
  EXPECT_EQ(paramString(app.modules[0].params, "label", ""), "a=b c");
  EXPECT_EQ(paramString(app.modules[0].params, "count", ""), "2");
}

TEST(Overrides, ABadValueIsReportedAtTheSettingNotInTheFile) {
  auto app = load();
  ASSERT_TRUE(applyOverrides(app, {"src.count=11"}).ok());
  const auto problems = validate(app, testing::testCatalog());
  ASSERT_EQ(problems.size(), 1u) << formatDiagnostics(problems);
  EXPECT_EQ(problems[0].loc.file, "--set src.count=11");
  EXPECT_EQ(problems[0].loc.line, 0);
  const std::string text = formatDiagnostic(problems[0]);
  EXPECT_EQ(text.rfind("--set src.count=11: error: ", 0), 0u) << text;
}

TEST(Overrides, AnUnknownParameterIsAValidationError) {
  auto app = load();
  ASSERT_TRUE(applyOverrides(app, {"src.cuont=1"}).ok());
  const auto problems = validate(app, testing::testCatalog());
  ASSERT_EQ(problems.size(), 1u) << formatDiagnostics(problems);
  EXPECT_NE(problems[0].message.find("no parameter 'cuont'"), std::string::npos)
      << problems[0].message;
}

TEST(Overrides, MalformedSettingsAndUnknownIdsAreRefusedByName) {
  for (const char* bad : {"count=1", "src.count", ".count=1", "src.=1", "=1", ""}) {
    auto app = load();
    const auto status = applyOverrides(app, {bad});
    ASSERT_FALSE(status.ok()) << bad;
    EXPECT_NE(status.error().message.find("expected ID.PARAM=VALUE"), std::string::npos)
        << status.error().message;
  }
  auto app = load();
  const auto status = applyOverrides(app, {"src.count=1", "nope.count=1"});
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message,
            "--set 'nope.count=1': the application has no module, filter or instance 'nope'");
}

// An instance of the file's own composite `sinks` (n sinks behind a broadcast).
constexpr std::string_view kInstanceApp = R"(<application name="y" version="1">
  <hosts><host id="h" address="127.0.0.1"/></hosts>
  <composites>
    <composite name="sinks">
      <param name="n" default="2" min="1" max="8"/>
      <input name="in" to="fan.in"/>
      <modules>
        <repeat var="i" count="${n}"><module id="s${i}" package="core" type="sink"/></repeat>
      </modules>
      <filters><filter id="fan" type="broadcast"/></filters>
      <connections>
        <repeat var="i" count="${n}"><connection from="fan.out" to="s${i}.in"/></repeat>
      </connections>
    </composite>
  </composites>
  <modules>
    <module id="src" package="core" type="source" host="h"/>
  </modules>
  <instances>
    <instance id="many" composite="sinks" host="h"/>
  </instances>
  <connections>
    <connection from="src.out" to="many.in"/>
  </connections>
</application>
)";

TEST(Overrides, AnInstanceOfTheFileIsSetBeforeExpansionTheRestAfter) {
  auto app = loadApplicationString(kInstanceApp, "app.xml", nullptr);
  ASSERT_TRUE(app.ok()) << app.error().message;
  std::vector<std::string> settings{"many.n=5", "src.count=4"};
  applyInstanceOverrides(*app, settings);
  EXPECT_EQ(settings, std::vector<std::string>{"src.count=4"}) << "left for after expansion";
  auto flat = expandComposites(*app, CompositeSources{}, nullptr);
  ASSERT_TRUE(flat.ok()) << flat.error().message;
  ASSERT_TRUE(applyOverrides(*flat, settings).ok());
  EXPECT_EQ(flat->modules.size(), 6u) << "src and 5 sinks";
  const auto problems = validate(*flat, testing::testCatalog());
  EXPECT_TRUE(problems.empty()) << formatDiagnostics(problems);
}

TEST(Overrides, ABadInstanceValueIsReportedAtTheSetting) {
  auto app = loadApplicationString(kInstanceApp, "app.xml", nullptr);
  ASSERT_TRUE(app.ok()) << app.error().message;
  std::vector<std::string> settings{"many.n=9"};
  applyInstanceOverrides(*app, settings);
  std::vector<Diagnostic> problems;
  auto flat = expandComposites(*app, CompositeSources{}, &problems);
  ASSERT_TRUE(hasErrors(problems)) << "n above its max";
  const std::string text = formatDiagnostics(problems);
  EXPECT_NE(text.find("--set many.n=9"), std::string::npos) << text;
}

}  // namespace
}  // namespace vrflow::app
