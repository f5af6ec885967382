#include "vrflow/app/validate.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "test_support.hpp"
#include "vrflow/app/loader.hpp"

namespace vrflow::app {
namespace {

using testing::check;

TEST(Validate, EveryValidDataFileHasNoDiagnostics) {
  int checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(testing::dataDir())) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("valid", 0) != 0) continue;
    const std::vector<Diagnostic> found =
        checkApplicationFile(entry.path().string(), testing::testCatalog());
    EXPECT_TRUE(found.empty()) << name << "\n" << formatDiagnostics(found);
    ++checked;
  }
  EXPECT_GE(checked, 4);
}

TEST(Validate, DuplicateModuleIdIsReportedAtTheSecondId) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a" package="core" type="relay"/>
    <module id="a" package="core" type="relay"/>
  </modules>
</application>
)"),
                       4, 13, "duplicate id 'a' (already used by the module at line 3)");
}

TEST(Validate, ModulesAndFiltersShareOneIdNamespace) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a" package="core" type="relay"/>
  </modules>
  <filters>
    <filter id="a" type="passthrough"/>
  </filters>
</application>
)"),
                       6, 13, "duplicate id 'a' (already used by the module at line 3)");
}

TEST(Validate, DuplicateHostIdIsReportedAtTheSecondId) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <hosts>
    <host id="h"/>
    <host id="h" address="10.0.0.1"/>
  </hosts>
</application>
)"),
                       4, 11, "duplicate host id 'h' (first defined at line 3)");
}

TEST(Validate, IdWithADotIsRejected) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a.b" package="core" type="relay"/>
  </modules>
</application>
)"),
                       3, 13, "id 'a.b' must not contain '.'");
}

TEST(Validate, UnknownHostIsReportedAtTheHostAttribute) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <hosts>
    <host id="node1"/>
    <host id="node2"/>
  </hosts>
  <modules>
    <module id="a" package="core" type="relay" host="node3"/>
  </modules>
</application>
)"),
                       7, 48, "unknown host 'node3' (hosts: node1, node2)");
}

TEST(Validate, UnknownPackageIsReportedAtThePackageAttribute) {
  const auto found = check(R"(<application>
  <modules>
    <module id="a" package="cor" type="relay"/>
  </modules>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 3, 20, "unknown package 'cor' (packages: core, physics)");
  EXPECT_NE(found[0].message.find("did you mean 'core'?"), std::string::npos);
}

TEST(Validate, UnknownModuleTypeListsTheTypesOfItsPackage) {
  const auto found = check(R"(<application>
  <modules>
    <module id="a" package="core" type="sourse"/>
  </modules>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 3, 35, "unknown module type 'core/sourse'");
  EXPECT_EQ(found[0].message,
            "unknown module type 'core/sourse' (known in package core: relay, sink, source); "
            "did you mean 'source'?");
}

TEST(Validate, UnknownFilterTypeListsTheKnownFilters) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <filters>
    <filter id="f" type="mrge"/>
  </filters>
</application>
)"),
                       3, 20,
                       "unknown filter type 'mrge' (known: broadcast, decimate, gate, gather, "
                       "initial, latest, maxfrequency, merge, multiplex, passthrough, repeat, "
                       "rotate and 5 more); did you mean 'merge'?");
}

TEST(Validate, ConnectionFromAMissingNodeIsReportedAtFrom) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="sink" package="core" type="sink"/>
  </modules>
  <connections>
    <connection from="src.out" to="sink.in"/>
  </connections>
</application>
)"),
                       6, 17, "no module or filter 'src' (known: sink)");
}

TEST(Validate, ConnectionToAMissingPortSaysWhichPortsExist) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="src" package="core" type="source"/>
    <module id="sink" package="core" type="sink"/>
  </modules>
  <connections>
    <connection from="src.out" to="sink.input"/>
    <connection from="src.out" to="sink.in"/>
  </connections>
</application>
)"),
                       7, 32,
                       "module 'sink' (core/sink) has no input 'input' (inputs: in, beginIt)");
}

TEST(Validate, ConnectionFromAMissingOutputSaysWhichOutputsExist) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="src" package="core" type="source"/>
    <module id="sink" package="core" type="sink"/>
  </modules>
  <connections>
    <connection from="src.output" to="sink.in"/>
  </connections>
</application>
)"),
                       7, 17,
                       "module 'src' (core/source) has no output 'output' (outputs: out, endIt)");
}

TEST(Validate, ConnectionFromAnInputIsReported) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a" package="core" type="relay"/>
    <module id="b" package="core" type="relay"/>
  </modules>
  <connections>
    <connection from="a.in" to="b.in"/>
  </connections>
</application>
)"),
                       7, 17,
                       "'a.in' is an input of module 'a' (core/relay); a connection goes from an "
                       "output to an input");
}

TEST(Validate, ConnectionToAnOutputIsReported) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a" package="core" type="relay"/>
    <module id="b" package="core" type="relay"/>
  </modules>
  <connections>
    <connection from="a.out" to="b.out"/>
  </connections>
</application>
)"),
                       7, 30, "'b.out' is an output of module 'b' (core/relay)");
}

TEST(Validate, DifferentDataTypesAreReportedAtTheConnection) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="src" package="core" type="source"/>
    <module id="view" package="physics" type="viewer"/>
  </modules>
  <connections>
    <connection from="src.out" to="view.objects"/>
  </connections>
</application>
)"),
                       7, 5,
                       "port data types differ: 'src.out' sends 'numbers' but 'view.objects' "
                       "expects 'objects'");
}

TEST(Validate, AnyDataMatchesEveryType) {
  EXPECT_TRUE(check(R"(<application>
  <modules>
    <module id="src" package="core" type="source"/>
    <module id="relay" package="core" type="relay"/>
    <module id="view" package="physics" type="viewer"/>
  </modules>
  <connections>
    <connection from="src.out" to="relay.in"/>
    <connection from="relay.out" to="view.objects"/>
  </connections>
</application>
)")
                  .empty());
}

TEST(Validate, StampsOnlyOutputIntoAFullMessageInputIsReported) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a" package="core" type="relay"/>
    <module id="b" package="core" type="relay"/>
  </modules>
  <connections>
    <connection from="a.endIt" to="b.in"/>
  </connections>
</application>
)"),
                       7, 5,
                       "'a.endIt' sends stamps-only messages but 'b.in' expects full messages");
}

TEST(Validate, StampsOnlyMessagesThroughFiltersIntoAFullMessageInputAreReported) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a" package="core" type="relay"/>
    <module id="b" package="core" type="relay"/>
  </modules>
  <filters>
    <filter id="p" type="passthrough"/>
    <filter id="q" type="passthrough"/>
  </filters>
  <connections>
    <connection from="a.endIt" to="p.in"/>
    <connection from="p.out" to="q.in"/>
    <connection from="q.out" to="b.in"/>
  </connections>
</application>
)"),
                       13, 5,
                       "'q.out' sends stamps-only messages (all its inputs are stamps-only) but "
                       "'b.in' expects full messages");
}

TEST(Validate, FilterWithAFullInputMayFeedAFullMessageInput) {
  EXPECT_TRUE(check(R"(<application>
  <modules>
    <module id="a" package="core" type="relay">
      <input port="in" initial-messages="1"/>
    </module>
    <module id="b" package="core" type="relay"/>
  </modules>
  <filters>
    <filter id="m" type="merge"/>
  </filters>
  <connections>
    <connection from="a.endIt" to="m.in0"/>
    <connection from="a.out" to="m.in1"/>
    <connection from="m.out" to="b.in"/>
    <connection from="b.out" to="a.in"/>
  </connections>
</application>
)")
                  .empty());
}

TEST(Validate, FullMessagesIntoAStampsOnlyInputAreFine) {
  EXPECT_TRUE(check(R"(<application>
  <modules>
    <module id="a" package="physics" type="animator"/>
    <module id="v" package="physics" type="viewer"/>
  </modules>
  <connections>
    <connection from="a.objects" to="v.objects"/>
    <connection from="a.objects" to="v.sync"/>
    <connection from="a.objects" to="v.beginIt"/>
  </connections>
</application>
)")
                  .empty());
}

TEST(Validate, RequiredInputLeftUnconnectedIsReportedAtTheModule) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="sink" package="core" type="sink"/>
  </modules>
</application>
)"),
                       3, 5, "required input 'in' of module 'sink' (core/sink) is not connected");
}

TEST(Validate, UnconnectedFilterInputIsReportedAtTheFilter) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <filters>
    <filter id="p" type="passthrough"/>
  </filters>
</application>
)"),
                       3, 5, "required input 'in' of filter 'p' (passthrough) is not connected");
}

TEST(Validate, InputSettingsForAMissingInputAreReportedAtThePort) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a" package="physics" type="animator">
      <input port="event" initial-messages="1"/>
    </module>
  </modules>
</application>
)"),
                       4, 14,
                       "module 'a' (physics/animator) has no input 'event' (inputs: events, "
                       "beginIt); did you mean 'events'?");
}

TEST(Validate, InputSettingsForAnOutputAreReported) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a" package="physics" type="animator">
      <input port="objects"/>
    </module>
  </modules>
</application>
)"),
                       4, 14, "'objects' is an output of module 'a' (physics/animator)");
}

TEST(Validate, InputConfiguredTwiceIsReported) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a" package="physics" type="animator">
      <input port="events"/>
      <input port="events" mode="latest"/>
    </module>
  </modules>
</application>
)"),
                       5, 7, "input 'events' of module 'a' is configured twice (first at line 4)");
}

TEST(Validate, NegativeInitialMessagesAreReportedAtTheAttribute) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a" package="physics" type="animator">
      <input port="events" initial-messages="-1"/>
    </module>
  </modules>
</application>
)"),
                       4, 28, "initial-messages must not be negative, got -1");
}

TEST(Validate, UndeclaredParameterIsReportedAtItsName) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="s" package="core" type="source">
      <param name="cont" value="1"/>
    </module>
  </modules>
</application>
)"),
                       4, 14,
                       "module 's' (core/source) has no parameter 'cont' (parameters: count, rate, "
                       "mode, offset, verbose, label); did you mean 'count'?");
}

TEST(Validate, ParameterValueOfTheWrongTypeIsReportedAtTheValue) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="s" package="core" type="source">
      <param name="count" value="three"/>
    </module>
  </modules>
</application>
)"),
                       4, 27,
                       "parameter 'count' of module 's' (core/source) expects an int, got 'three'");
}

TEST(Validate, ParameterOutOfRangeIsReportedAtTheValue) {
  EXPECT_ONLY_ERROR_AT(
      check(R"(<application>
  <modules>
    <module id="s" package="core" type="source">
      <param name="rate" value="0.25"/>
    </module>
  </modules>
</application>
)"),
      4, 26, "parameter 'rate' of module 's' (core/source) is 0.25, below its minimum 0.5");
}

TEST(Validate, EnumVectorAndBoolParametersAreChecked) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <modules>
    <module id="s" package="core" type="source">
      <param name="mode" value="medium"/>
      <param name="offset" value="1 2"/>
      <param name="verbose" value="yes"/>
      <param name="count" value="10"/>
    </module>
  </modules>
</application>
)");
  ASSERT_EQ(found.size(), 3u) << formatDiagnostics(found);
  EXPECT_EQ(found[0].loc.line, 4);
  EXPECT_NE(found[0].message.find("expects one of fast, slow, got 'medium'"), std::string::npos);
  EXPECT_EQ(found[1].loc.line, 5);
  EXPECT_NE(found[1].message.find("expects 3 numbers 'x y z', got '1 2'"), std::string::npos);
  EXPECT_EQ(found[2].loc.line, 6);
  EXPECT_NE(found[2].message.find("expects a bool"), std::string::npos);
}

TEST(Validate, ParameterSetTwiceIsReported) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="s" package="core" type="source">
      <param name="count" value="1"/>
      <param name="count" value="2"/>
    </module>
  </modules>
</application>
)"),
                       5, 14, "parameter 'count' is set twice on module 's' (core/source)");
}

TEST(Validate, FilterParametersAreCheckedAndShapeItsPorts) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <modules>
    <module id="a" package="core" type="source"/>
    <module id="b" package="core" type="sink"/>
  </modules>
  <filters>
    <filter id="m" type="merge">
      <param name="inputs" value="3"/>
    </filter>
    <filter id="bad" type="merge">
      <param name="inputs" value="0"/>
    </filter>
  </filters>
  <connections>
    <connection from="a.out" to="m.in0"/>
    <connection from="a.out" to="m.in1"/>
    <connection from="a.out" to="m.in2"/>
    <connection from="m.out" to="b.in"/>
    <connection from="a.out" to="bad.in0"/>
  </connections>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 11, 28,
                       "parameter 'inputs' of filter 'bad' (merge) is 0, below its minimum 1");
}

TEST(Validate, ParametersThatMustAgreeAreCheckedTogether) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <modules>
    <module id="a" package="core" type="source"/>
    <module id="b" package="core" type="sink"/>
  </modules>
  <filters>
    <filter id="s" type="scatter">
      <param name="by" value="type"/>
      <param name="outputs" value="3"/>
      <param name="types" value="rigid, point"/>
    </filter>
    <filter id="t" type="typefilter"/>
    <filter id="ok" type="typefilter">
      <param name="types" value="rigid"/>
    </filter>
  </filters>
  <connections>
    <connection from="a.out" to="s.in"/>
    <connection from="s.out0" to="b.in"/>
    <connection from="a.out" to="t.in"/>
    <connection from="t.out" to="b.in"/>
    <connection from="a.out" to="ok.in"/>
    <connection from="ok.out" to="b.in"/>
  </connections>
</application>
)");
  ASSERT_EQ(found.size(), 2u) << formatDiagnostics(found);
  EXPECT_EQ(found[0].loc.line, 7);
  EXPECT_EQ(found[0].message,
            "filter 's' (scatter): by=\"type\" needs one type name in 'types' per output: 3 "
            "outputs, 2 names");
  EXPECT_EQ(found[1].loc.line, 12);
  EXPECT_NE(found[1].message.find("filter 't' (typefilter): parameter 'types' must list"),
            std::string::npos)
      << found[1].message;
}

TEST(Validate, ScatterByBoundsNeedsOneCutFewerThanOutputsIncreasing) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <modules>
    <module id="a" package="core" type="source"/>
    <module id="b" package="core" type="sink"/>
  </modules>
  <filters>
    <filter id="n" type="scatter">
      <param name="by" value="bounds"/><param name="outputs" value="3"/><param name="cuts" value="1"/>
    </filter>
    <filter id="d" type="scatter">
      <param name="by" value="bounds"/><param name="outputs" value="3"/><param name="cuts" value="2,1"/>
    </filter>
    <filter id="w" type="scatter">
      <param name="by" value="bounds"/><param name="cuts" value="wide"/>
    </filter>
    <filter id="c" type="scatter">
      <param name="cuts" value="1"/>
    </filter>
    <filter id="ok" type="scatter">
      <param name="by" value="bounds"/><param name="outputs" value="3"/><param name="axis" value="z"/>
      <param name="cuts" value="-1.5, 2"/>
    </filter>
  </filters>
  <connections>
    <connection from="a.out" to="n.in"/>
    <connection from="n.out0" to="b.in"/>
    <connection from="a.out" to="d.in"/>
    <connection from="d.out0" to="b.in"/>
    <connection from="a.out" to="w.in"/>
    <connection from="w.out0" to="b.in"/>
    <connection from="a.out" to="c.in"/>
    <connection from="c.out0" to="b.in"/>
    <connection from="a.out" to="ok.in"/>
    <connection from="ok.out0" to="b.in"/>
  </connections>
</application>
)");
  ASSERT_EQ(found.size(), 4u) << formatDiagnostics(found);
  EXPECT_EQ(found[0].message,
            "filter 'n' (scatter): by=\"bounds\" needs N-1 numbers in 'cuts' for N outputs: 3 "
            "outputs, 1 cuts");
  EXPECT_EQ(found[1].message, "filter 'd' (scatter): 'cuts' must be strictly increasing");
  EXPECT_EQ(found[2].message, "filter 'w' (scatter): 'cuts': 'wide' is not a finite number");
  EXPECT_EQ(found[3].message,
            "filter 'c' (scatter): parameter 'cuts' applies only with by=\"bounds\"");
}

TEST(Validate, NegativeCapacityIsReportedAtTheAttribute) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a" package="core" type="source"/>
    <module id="b" package="core" type="sink"/>
  </modules>
  <connections>
    <connection from="a.out" to="b.in" capacity="-3"/>
  </connections>
</application>
)"),
                       7, 40, "capacity must not be negative, got -3");
}

TEST(Validate, DuplicateConnectionIsAWarning) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <modules>
    <module id="a" package="core" type="source"/>
    <module id="b" package="core" type="sink"/>
  </modules>
  <connections>
    <connection from="a.out" to="b.in"/>
    <connection from="a.out" to="b.in"/>
  </connections>
</application>
)");
  ASSERT_EQ(found.size(), 1u) << formatDiagnostics(found);
  EXPECT_EQ(found[0].severity, Diagnostic::Warning);
  EXPECT_EQ(found[0].loc.line, 8);
  EXPECT_FALSE(hasErrors(found));
}

TEST(Validate, EditorPositionOfAnUnknownNodeIsAWarning) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <editor>
    <node ref="ghost" x="1"/>
  </editor>
</application>
)");
  ASSERT_EQ(found.size(), 1u) << formatDiagnostics(found);
  EXPECT_EQ(found[0].severity, Diagnostic::Warning);
  EXPECT_EQ(formatDiagnostic(found[0]),
            "app.xml:3:11: warning: editor position for unknown module or filter 'ghost'");
}

TEST(Validate, AllProblemsComeSortedByLineAndEachOnce) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <hosts>
    <host id="h" adress="x"/>
  </hosts>
  <modules>
    <module id="s" package="core" type="source" host="g"/>
    <module package="core" type="relay"/>
    <module id="t" package="core" type="sink">
      <param name="x" value="1"/>
    </module>
  </modules>
  <connections>
    <connection from="s.out" to="t.in" capacity="-1" policy="fast"/>
  </connections>
</application>
)");
  ASSERT_EQ(found.size(), 6u) << formatDiagnostics(found);
  const std::vector<std::pair<int, int>> expected = {{3, 18}, {6, 49},  {7, 5},
                                                     {9, 14}, {13, 40}, {13, 54}};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(found[i].loc.line, expected[i].first) << formatDiagnostics(found);
    EXPECT_EQ(found[i].loc.column, expected[i].second) << formatDiagnostics(found);
  }
}

TEST(Validate, ModelBuiltInCodeIsValidatedWithoutLocations) {
  Application app;
  Module sink;
  sink.id = "sink";
  sink.package = "core";
  sink.type = "sink";
  Module unnamed;
  unnamed.package = "core";
  unnamed.type = "relay";
  app.modules = {sink, unnamed};
  const std::vector<Diagnostic> found = validate(app, testing::testCatalog());
  ASSERT_EQ(found.size(), 2u) << formatDiagnostics(found);
  EXPECT_EQ(formatDiagnostic(found[0]),
            "error: required attribute 'id' of <module> is missing or empty");
  EXPECT_EQ(formatDiagnostic(found[1]),
            "error: required input 'in' of module 'sink' (core/sink) is not connected");
}

TEST(FormatDiagnostic, WritesFileLineColumnSeverityAndMessage) {
  Diagnostic diagnostic;
  diagnostic.loc.file = "a.xml";
  diagnostic.loc.line = 3;
  diagnostic.loc.column = 7;
  diagnostic.message = "bad";
  EXPECT_EQ(formatDiagnostic(diagnostic), "a.xml:3:7: error: bad");
  diagnostic.severity = Diagnostic::Warning;
  diagnostic.loc.line = 0;
  EXPECT_EQ(formatDiagnostic(diagnostic), "a.xml: warning: bad");
}

TEST(Validate, HostAddressMustBeAnIpv4AddressOrAHostName) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <hosts>
    <host id="a" address="999.1.1.1"/>
  </hosts>
</application>
)"),
                       3, 18,
                       "address '999.1.1.1' of host 'a' is not a valid IPv4 address (four numbers "
                       "0-255 separated by dots)");
  const std::vector<Diagnostic> bad = check(R"(<application>
  <hosts>
    <host id="a" address="1.2.3"/>
    <host id="b" address="node_1"/>
    <host id="c" address="-node"/>
  </hosts>
</application>
)");
  EXPECT_EQ(bad.size(), 3u) << formatDiagnostics(bad);
  const std::vector<Diagnostic> good = check(R"(<application>
  <hosts>
    <host id="a" address="10.0.0.255"/>
    <host id="b" address="node-1.cluster.example"/>
    <host id="c" address="localhost"/>
  </hosts>
</application>
)");
  EXPECT_TRUE(good.empty()) << formatDiagnostics(good);
}

TEST(Validate, IdWithANewlineOrAControlCharacterIsRefused) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a&#10;b" package="core" type="source"/>
  </modules>
</application>
)"),
                       3, 13, "id 'a\\nb' contains a control character (U+000A)");
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <hosts>
    <host id="h&#9;1"/>
  </hosts>
</application>
)"),
                       3, 11, "id 'h\\t1' contains a control character (U+0009)");
}

TEST(Validate, OutOfRangePortCountIsTheOnlyErrorNotHundredsOfUnconnectedInputs) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <filters>
    <filter id="m" type="merge">
      <param name="inputs" value="1000000"/>
    </filter>
  </filters>
</application>
)"),
                       4, 28, "parameter 'inputs' of filter 'm' (merge)");
}

TEST(Validate, BadEndpointIsReportedNotTheInputItMeantToFeed) {
  // Before: "required input 'in' of module 'b' is not connected" came first (line 4).
  const std::vector<Diagnostic> wrongPort = check(R"(<application>
  <modules>
    <module id="a" package="core" type="source"/>
    <module id="b" package="core" type="sink"/>
  </modules>
  <connections>
    <connection from="a.out" to="b.inn"/>
  </connections>
</application>
)");
  EXPECT_ONLY_ERROR_AT(wrongPort, 7, 30,
                       "has no input 'inn' (inputs: in, beginIt); did you mean 'in'?");
  const std::vector<Diagnostic> wrongNode = check(R"(<application>
  <modules>
    <module id="a" package="core" type="source"/>
    <module id="sink" package="core" type="sink"/>
  </modules>
  <connections>
    <connection from="a.out" to="snik.in"/>
  </connections>
</application>
)");
  EXPECT_ONLY_ERROR_AT(wrongNode, 7, 30, "no module or filter 'snik'");
}

}  // namespace
}  // namespace vrflow::app
