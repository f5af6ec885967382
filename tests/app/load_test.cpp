#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vrflow/app/loader.hpp"

namespace vrflow::app {
namespace {

using testing::check;

std::vector<Diagnostic> loadProblems(std::string_view xml) {
  std::vector<Diagnostic> problems;
  const Result<Application> app = loadApplicationString(xml, "app.xml", &problems);
  EXPECT_TRUE(app.ok());
  return problems;
}

TEST(LoadApplication, MalformedXmlFailsWithFileLineAndColumn) {
  const Result<Application> app = loadApplicationString(R"(<application name="x" version="1">
  <modules>
    <module id="a" package="core" type="source">
  </modules>
</application>
)",
                                                        "broken.xml");
  ASSERT_FALSE(app.ok());
  EXPECT_EQ(app.error().message, "broken.xml:4:5: error: Start-end tags mismatch");
}

TEST(LoadApplication, MalformedXmlIsOneDiagnosticWhenChecking) {
  const std::vector<Diagnostic> found = check("<application>\n  <hosts>\n    <host id=\"a\n");
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].loc.file, "app.xml");
  EXPECT_EQ(found[0].loc.line, 3);
  EXPECT_GT(found[0].loc.column, 0);
}

TEST(LoadApplication, EmptyTextIsMalformed) {
  const Result<Application> app = loadApplicationString("", "empty.xml");
  ASSERT_FALSE(app.ok());
  EXPECT_EQ(app.error().message, "empty.xml:1:1: error: No document element found");
}

TEST(LoadApplication, FileWithoutHostsGetsAnImplicitLocalhost) {
  const Result<Application> app = loadApplicationFile(testing::dataDir() + "/valid_pipeline.xml");
  ASSERT_TRUE(app.ok()) << app.error().message;
  ASSERT_EQ(app->hosts.size(), 1u);
  EXPECT_EQ(app->hosts[0].id, "localhost");
  EXPECT_EQ(app->hosts[0].address, "127.0.0.1");
  EXPECT_EQ(app->modules[0].host, "localhost");
  EXPECT_EQ(app->file, testing::dataDir() + "/valid_pipeline.xml");
}

TEST(LoadApplication, ModulesAndFiltersWithoutHostRunOnTheFirstHost) {
  const Result<Application> app = loadApplicationFile(testing::dataDir() + "/valid_cluster.xml");
  ASSERT_TRUE(app.ok()) << app.error().message;
  EXPECT_EQ(findModule(*app, "left")->host, "node1");
  EXPECT_EQ(findModule(*app, "sink")->host, "front");
  EXPECT_EQ(findFilter(*app, "join")->host, "front");
  EXPECT_EQ(findFilter(*app, "fanout")->host, "node1");
  EXPECT_EQ(findHost(*app, "node2")->address, "127.0.0.1");
}

TEST(LoadApplication, ReadsTheEndItTimingOfAModule) {
  const Result<Application> app = loadApplicationFile(testing::dataDir() + "/valid_physics.xml");
  ASSERT_TRUE(app.ok()) << app.error().message;
  EXPECT_EQ(findModule(*app, "inter")->endIt, EndItTiming::AfterWait);
  EXPECT_EQ(findModule(*app, "anim")->endIt, EndItTiming::AfterIteration);
}

TEST(LoadApplication, ReadsEveryElementInFileOrder) {
  const Result<Application> app = loadApplicationFile(testing::dataDir() + "/valid_cluster.xml");
  ASSERT_TRUE(app.ok()) << app.error().message;
  EXPECT_EQ(app->name, "cluster");
  ASSERT_EQ(app->modules.size(), 4u);
  EXPECT_EQ(app->modules[0].id, "left");
  EXPECT_EQ(app->modules[3].id, "relay");
  const Module& left = app->modules[0];
  EXPECT_EQ(paramInt(left.params, "count", 0), 3);
  EXPECT_EQ(paramString(left.params, "mode", ""), "slow");
  EXPECT_EQ(paramString(findModule(*app, "right")->params, "label", ""), "right & <tagged> \"x\"");
  const Module& relay = app->modules[3];
  ASSERT_EQ(relay.inputs.size(), 2u);
  EXPECT_EQ(relay.inputs[0].initialMessages, 2);
  EXPECT_EQ(relay.inputs[1].port, "beginIt");
  EXPECT_EQ(findModule(*app, "sink")->inputs[0].mode, InputMode::Latest);
  ASSERT_EQ(app->connections.size(), 6u);
  EXPECT_EQ(app->connections[1].from.node, "right");
  EXPECT_EQ(app->connections[1].to.port, "in1");
  EXPECT_EQ(app->connections[1].capacity, 4);
  EXPECT_EQ(app->connections[1].policy, QueuePolicy::DropOldest);
  ASSERT_EQ(app->editor.size(), 4u);
  EXPECT_EQ(app->editor[0].y, 20.5);
  EXPECT_EQ(app->editor[1].x, 0);
  EXPECT_EQ(findEditorNode(*app, "join")->x, 200.25);
}

TEST(LoadApplication, RecordsTheLineAndColumnOfEveryElementAndAttribute) {
  const Result<Application> app = loadApplicationFile(testing::dataDir() + "/valid_cluster.xml");
  ASSERT_TRUE(app.ok()) << app.error().message;
  const Module& left = app->modules[0];
  EXPECT_EQ(left.loc.line, 9);
  EXPECT_EQ(left.loc.column, 5);
  EXPECT_EQ(left.loc.attribute("host").line, 9);
  EXPECT_EQ(left.loc.attribute("host").column, 52);
  EXPECT_EQ(left.params[1].loc.line, 11);
  EXPECT_EQ(left.params[1].loc.column, 7);
  EXPECT_EQ(app->connections[0].loc.line, 33);
  EXPECT_EQ(app->connections[0].loc.attribute("to").column, 33);
  EXPECT_EQ(app->hosts[2].loc.line, 6);
  EXPECT_EQ(app->editor[3].loc.line, 44);
}

TEST(LoadApplication, ColumnsCountCharactersNotBytes) {
  const std::vector<Diagnostic> found =
      loadProblems("<application name=\"d\xC3\xA9j\xC3\xA0 vu\" colour=\"red\"/>");
  EXPECT_ONLY_ERROR_AT(found, 1, 29, "unknown attribute 'colour'");
}

TEST(LoadApplication, WindowsLineEndingsCountOneLineEach) {
  const std::vector<Diagnostic> found = loadProblems(
      "<application>\r\n  <modules>\r\n    <modul id=\"a\"/>\r\n  "
      "</modules>\r\n</application>\r\n");
  EXPECT_ONLY_ERROR_AT(found, 3, 5, "unknown element <modul>");
}

TEST(LoadApplication, UnknownElementIsReportedAtItsTag) {
  const std::vector<Diagnostic> found = loadProblems(R"(<application name="x" version="1">
  <modules>
    <module id="a" package="core" type="source">
      <parameter name="count" value="1"/>
    </module>
  </modules>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 4, 7,
                       "unknown element <parameter> in <module> (allowed: param, input)");
}

TEST(LoadApplication, UnknownAttributeIsReportedAtTheAttributeWithASuggestion) {
  const std::vector<Diagnostic> found = loadProblems(R"(<application name="x">
  <modules>
    <module id="a" package="core" type="source" hots="h1"/>
  </modules>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 3, 49, "unknown attribute 'hots' on <module>");
  EXPECT_NE(found[0].message.find("did you mean 'host'?"), std::string::npos);
}

TEST(LoadApplication, MissingRequiredAttributeIsReportedAtTheElement) {
  const std::vector<Diagnostic> found = loadProblems(R"(<application name="x">
  <modules>
    <module id="a" type="source"/>
  </modules>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 3, 5, "required attribute 'package' of <module> is missing");
}

TEST(LoadApplication, BadNumberIsReportedAtTheAttribute) {
  const std::vector<Diagnostic> found = loadProblems(R"(<application name="x">
  <connections>
    <connection from="a.out" to="b.in" capacity="many"/>
  </connections>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 3, 40, "attribute 'capacity' of <connection> must be an integer");
}

TEST(LoadApplication, BadKeywordIsReportedAtTheAttribute) {
  const std::vector<Diagnostic> found = loadProblems(R"(<application name="x">
  <connections>
    <connection from="a.out" to="b.in" policy="drop"/>
  </connections>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 3, 40,
                       "attribute 'policy' of <connection> must be one of block, drop-oldest, "
                       "drop-newest, got 'drop'");
}

TEST(LoadApplication, NonFiniteEditorPositionIsRejected) {
  const std::vector<Diagnostic> found = loadProblems(
      "<application>\n  <editor>\n    <node ref=\"a\" x=\"nan\"/>\n  </editor>\n"
      "</application>\n");
  EXPECT_ONLY_ERROR_AT(found, 3, 19, "must be a finite number");
}

TEST(LoadApplication, EndpointWithoutDotIsReportedOnceAtTheAttribute) {
  const std::vector<Diagnostic> found = check(R"(<application name="x">
  <connections>
    <connection from="a" to="b.in"/>
  </connections>
</application>
)");
  ASSERT_GE(found.size(), 1u);
  EXPECT_EQ(found[0].loc.line, 3);
  EXPECT_EQ(found[0].loc.column, 17);
  EXPECT_EQ(found[0].message, "endpoint 'a' must be written node.port");
  for (std::size_t i = 1; i < found.size(); ++i) {
    EXPECT_NE(found[i].message, found[0].message) << formatDiagnostics(found);
  }
}

TEST(LoadApplication, RepeatedAttributeIsReported) {
  const std::vector<Diagnostic> found = loadProblems(
      "<application>\n  <hosts>\n    <host id=\"a\" id=\"b\"/>\n  </hosts>\n"
      "</application>\n");
  EXPECT_ONLY_ERROR_AT(found, 3, 18, "attribute 'id' is repeated on <host>");
}

TEST(LoadApplication, SectionsOutOfOrderAreReported) {
  const std::vector<Diagnostic> found = loadProblems(R"(<application name="x">
  <connections/>
  <modules/>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 3, 3, "<modules> is out of order");
}

TEST(LoadApplication, RepeatedSectionIsReported) {
  const std::vector<Diagnostic> found =
      loadProblems("<application>\n  <modules/>\n  <modules/>\n</application>\n");
  EXPECT_ONLY_ERROR_AT(found, 3, 3, "<modules> appears twice");
}

TEST(LoadApplication, TextInsideAnElementIsReported) {
  const std::vector<Diagnostic> found =
      loadProblems("<application>\n  <hosts>oops</hosts>\n</application>\n");
  EXPECT_ONLY_ERROR_AT(found, 2, 10, "unexpected text in <hosts>");
}

TEST(LoadApplication, RootMustBeApplication) {
  const std::vector<Diagnostic> found = loadProblems("<?xml version=\"1.0\"?>\n<package/>\n");
  EXPECT_ONLY_ERROR_AT(found, 2, 1, "root element must be <application>, found <package>");
}

TEST(LoadApplication, UnsupportedVersionIsReportedAtTheAttribute) {
  const std::vector<Diagnostic> found = loadProblems("<application name=\"a\" version=\"2\"/>");
  EXPECT_ONLY_ERROR_AT(found, 1, 23, "unsupported format version '2'");
}

TEST(LoadApplication, WithoutAProblemListStructuralProblemsFailTheLoadAndAreAllListed) {
  const Result<Application> app = loadApplicationString(R"(<application name="x">
  <hosts>
    <host name="a"/>
  </hosts>
</application>
)",
                                                        "app.xml");
  ASSERT_FALSE(app.ok());
  EXPECT_EQ(app.error().message,
            "app.xml:3:5: error: required attribute 'id' of <host> is missing or empty\n"
            "app.xml:3:11: error: unknown attribute 'name' on <host> (allowed: id, address)");
}

TEST(LoadApplication, SchemaLocationAttributesAreAllowed) {
  EXPECT_TRUE(loadProblems("<application name=\"a\" "
                           "xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
                           "xsi:noNamespaceSchemaLocation=\"vrflow-application.xsd\"/>")
                  .empty());
}

TEST(LoadApplication, BadInputModeIsReportedAtTheAttribute) {
  const std::vector<Diagnostic> found = loadProblems(R"(<application>
  <modules>
    <module id="a" package="core" type="relay">
      <input port="in" mode="greedy"/>
    </module>
  </modules>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 4, 24, "attribute 'mode' of <input> must be one of fifo, latest");
}

TEST(LoadApplication, MissingFileFailsWithItsPath) {
  const Result<Application> app = loadApplicationFile("/nonexistent/app.xml");
  ASSERT_FALSE(app.ok());
  EXPECT_EQ(app.error().message,
            "/nonexistent/app.xml: error: cannot read file (No such file or directory)");
}

TEST(LoadApplication, InvalidUtf8IsRefusedAtItsLineAndColumn) {
  // Latin-1 "é" (0xE9) in an attribute: accepted and echoed raw before.
  const std::vector<Diagnostic> found = check(
      "<application>\n  <modules>\n    <module id=\"caf\xE9\" package=\"core\" "
      "type=\"source\"/>\n  </modules>\n</application>\n");
  EXPECT_ONLY_ERROR_AT(found, 3, 20, "invalid UTF-8 (byte 0xE9)");
  EXPECT_EQ(found[0].message.find('\xE9'), std::string::npos) << "the byte is not echoed";
}

TEST(LoadApplication, Utf16FileIsNamedAsUtf16WithHowToConvertIt) {
  const std::string utf8 = "<application>\n</application>\n";
  std::string utf16 = "\xFF\xFE";
  for (const char c : utf8) utf16 += std::string{c, '\0'};
  const std::vector<Diagnostic> found = check(utf16);
  ASSERT_EQ(found.size(), 1u) << formatDiagnostics(found);
  EXPECT_EQ(found[0].loc.file, "app.xml");
  EXPECT_NE(found[0].message.find("encoded in UTF-16LE"), std::string::npos) << found[0].message;
  EXPECT_NE(found[0].message.find("iconv -f UTF-16LE -t UTF-8"), std::string::npos);
  // Without a byte order mark too.
  const std::vector<Diagnostic> bare = check(utf16.substr(2));
  ASSERT_EQ(bare.size(), 1u) << formatDiagnostics(bare);
  EXPECT_NE(bare[0].message.find("UTF-16LE"), std::string::npos) << bare[0].message;
}

TEST(LoadApplication, RepeatedAttributeOfAMisplacedElementIsReportedToo) {
  // A <module> written outside <modules>: its repeated attribute was never mentioned.
  const std::vector<Diagnostic> found = loadProblems(
      "<application>\n  <module id=\"a\" id=\"b\" package=\"core\" type=\"relay\"/>\n"
      "</application>\n");
  ASSERT_EQ(found.size(), 2u) << formatDiagnostics(found);
  EXPECT_EQ(found[0].loc.column, 3);
  EXPECT_NE(found[0].message.find("unknown element <module> in <application>"), std::string::npos);
  EXPECT_EQ(found[1].loc.line, 2);
  EXPECT_EQ(found[1].loc.column, 18);
  EXPECT_NE(found[1].message.find("attribute 'id' is repeated on <module>"), std::string::npos);
}

}  // namespace
}  // namespace vrflow::app
