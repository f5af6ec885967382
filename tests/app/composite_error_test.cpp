// Problems in applications that use composites: where they are reported and what they say.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "composite_support.hpp"
#include "test_support.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/validate.hpp"

namespace vrflow::app {
namespace {

using testing::checkComposed;

// An application defining composite `c` with `body` (from line 3) and using it once as
// instance `w`, four lines below the body's last line, with nothing connected to it.
std::string oneInstance(const std::string& body, const std::string& instanceParams = "") {
  return "<application>\n  <composites>\n    <composite name=\"c\">" + body +
         "</composite>\n  </composites>\n"
         "  <modules><module id=\"numbers\" package=\"core\" type=\"source\"/></modules>\n"
         "  <instances>\n    <instance id=\"w\" composite=\"c\">" +
         instanceParams + "</instance>\n  </instances>\n</application>\n";
}

TEST(CompositeErrors, ErrorInsideACompositeFileNamesItsLineAndEveryInstanceLine) {
  const std::string app = testing::compositeDir() + "/broken_app.xml";
  const std::vector<Diagnostic> found = checkApplicationFile(app, testing::testCatalog());
  ASSERT_EQ(found.size(), 1u) << formatDiagnostics(found);
  EXPECT_EQ(found[0].loc.file, testing::compositeDir() + "/broken_type.vrc.xml");
  EXPECT_EQ(found[0].loc.line, 5);
  EXPECT_EQ(found[0].loc.column, 39);
  const std::string wraps = testing::compositeDir() + "/wraps_broken.vrc.xml";
  EXPECT_EQ(formatDiagnostic(found[0]),
            testing::compositeDir() +
                "/broken_type.vrc.xml:5:39: error: unknown module type 'core/relya' (known in "
                "package core: relay, sink, source); did you mean 'relay'?\n" +
                wraps + ":5:5: note: in instance 'w:deep' of composite 'broken_type'\n" + app +
                ":7:5: note: in instance 'w' of composite 'wraps_broken'");
}

TEST(CompositeErrors, ProblemOfTheFlatNetworkInsideACompositePointsIntoItWithANote) {
  const std::vector<Diagnostic> found = checkComposed(oneInstance(R"(
      <input name="in" to="s.in"/>
      <modules><module id="s" package="core" type="sink"/></modules>
      <filters><filter id="f" type="passthrough"/></filters>)"));
  // Required inputs left unconnected: the exposed `w.in` (that is `w:s.in`) and the filter's.
  ASSERT_EQ(found.size(), 2u) << formatDiagnostics(found);
  EXPECT_EQ(found[0].loc.line, 5);
  EXPECT_EQ(found[0].message, "required input 'in' of module 'w:s' (core/sink) is not connected");
  ASSERT_EQ(found[0].loc.expandedFrom.size(), 1u);
  EXPECT_EQ(found[0].loc.expandedFrom[0].line, 10);
  EXPECT_EQ(formatDiagnostic(found[0]),
            "app.xml:5:16: error: required input 'in' of module 'w:s' (core/sink) is not "
            "connected\napp.xml:10:5: note: in instance 'w' of composite 'c'");
  EXPECT_EQ(found[1].loc.line, 6);
  EXPECT_NE(found[1].message.find("filter 'w:f'"), std::string::npos) << found[1].message;
}

TEST(CompositeErrors, CompositeThatContainsItselfIsRefusedNamingTheChain) {
  const std::vector<Diagnostic> found = checkComposed(R"(<application>
  <composites>
    <composite name="a"><instances><instance id="x" composite="b"/></instances></composite>
    <composite name="b"><instances><instance id="y" composite="a"/></instances></composite>
  </composites>
  <instances>
    <instance id="top" composite="a"/>
  </instances>
</application>
)");
  ASSERT_EQ(found.size(), 1u) << formatDiagnostics(found);
  EXPECT_EQ(found[0].loc.line, 4);
  EXPECT_EQ(found[0].message, "composite 'a' contains itself: a -> b -> a");
  EXPECT_EQ(found[0].loc.expandedFrom.size(), 2u);
}

TEST(CompositeErrors, DataFlowCycleThroughACompositeWithoutInitialMessageIsADeadlock) {
  const std::string loop = R"(<application>
  <modules>
    <module id="anim" package="physics" type="animator"/>
  </modules>
  <instances>
    <instance id="p" composite="relay_pair"/>
  </instances>
  <connections>
    <connection from="anim.objects" to="p.in"/>
    <connection from="p.out" to="anim.events"/>
  </connections>
</application>
)";
  const std::vector<Diagnostic> found = checkComposed(loop);
  EXPECT_ONLY_ERROR_AT(found, 9, 5,
                       "cycle without initial message (would deadlock): anim.objects -> "
                       "p:first.in, p:first.out -> p:second.in, p:second.out -> anim.events");
  std::string started = loop;
  started.replace(started.find("type=\"animator\"/>"), 17,
                  "type=\"animator\"><input port=\"events\" initial-messages=\"1\"/></module>");
  EXPECT_TRUE(checkComposed(started).empty()) << formatDiagnostics(checkComposed(started));
}

TEST(CompositeErrors, InitialMessagesInsideACompositeStartACycleThroughIt) {
  const std::vector<Diagnostic> found = checkComposed(R"(<application>
  <composites>
    <composite name="starter">
      <input name="in" to="r.in"/>
      <output name="out" from="r.out"/>
      <modules>
        <module id="r" package="core" type="relay"><input port="in" initial-messages="${1}"/></module>
      </modules>
    </composite>
  </composites>
  <modules><module id="a" package="core" type="relay"/></modules>
  <instances><instance id="s" composite="starter"/></instances>
  <connections>
    <connection from="a.out" to="s.in"/>
    <connection from="s.out" to="a.in"/>
  </connections>
</application>
)");
  EXPECT_TRUE(found.empty()) << formatDiagnostics(found);
}

TEST(CompositeErrors, UnknownCompositeSuggestsTheClosestNameAndSaysWhereItLooked) {
  const std::vector<Diagnostic> found = checkComposed(
      "<application>\n  <instances>\n    <instance id=\"w\" composite=\"wrkers\"/>"
      "\n  </instances>\n</application>\n");
  EXPECT_ONLY_ERROR_AT(found, 3, 22, "unknown composite 'wrkers' (known: ");
  EXPECT_NE(found[0].message.find("searched for wrkers.vrc.xml in: " + testing::compositeDir()),
            std::string::npos);
  EXPECT_NE(found[0].message.find("did you mean 'workers'?"), std::string::npos);
}

TEST(CompositeErrors, CompositeFileMustBeNamedAfterTheCompositeItDefines) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("vrflow-composites-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "misnamed.vrc.xml") << "<composite name=\"other\" version=\"1\"/>\n";
  const Result<Application> app = loadApplicationString(
      R"(<application><instances><instance id="m" composite="misnamed"/></instances></application>)",
      "app.xml");
  ASSERT_TRUE(app.ok());
  CompositeSources sources;
  sources.searchPath.push_back(dir.string());
  std::vector<Diagnostic> problems;
  ASSERT_TRUE(expandComposites(*app, sources, &problems).ok());
  std::filesystem::remove_all(dir);
  EXPECT_ONLY_ERROR_AT(problems, 1, 12,
                       "this file defines composite 'other', but composite 'misnamed' is looked "
                       "up in it (a composite's file is named NAME.vrc.xml)");
  EXPECT_EQ(problems[0].loc.file, (dir / "misnamed.vrc.xml").string());
}

TEST(CompositeErrors, ParametersAreCheckedAgainstTheCompositesDeclarations) {
  const std::string body = R"(<param name="n" min="2" max="4"/><param name="label" default="x"/>)";
  EXPECT_ONLY_ERROR_AT(checkComposed(oneInstance(body)), 7, 5,
                       "instance 'w' of composite 'c' must set parameter 'n' (it has no default)");
  EXPECT_ONLY_ERROR_AT(checkComposed(oneInstance(body, R"(<param name="n" value="5"/>)")), 7, 52,
                       "parameter 'n' of instance 'w' of composite 'c' must be an integer in "
                       "[2, 4], got '5'");
  EXPECT_ONLY_ERROR_AT(
      checkComposed(
          oneInstance(body, R"(<param name="n" value="3"/><param name="lable" value="y"/>)")),
      7, 70,
      "composite 'c' has no parameter 'lable' (parameters: n, label); did you mean 'label'?");
}

TEST(CompositeErrors, ExposedPortsMustExistAndKeepTheirDirection) {
  const std::string app = R"(<application>
  <modules>
    <module id="numbers" package="core" type="source"/>
    <module id="sink" package="core" type="sink"/>
  </modules>
  <instances><instance id="p" composite="relay_pair"/></instances>
  <connections>
    <connection from="numbers.out" to="p.input"/>
    <connection from="p.in" to="sink.in"/>
  </connections>
</application>
)";
  const std::vector<Diagnostic> found = checkComposed(app);
  ASSERT_EQ(found.size(), 3u) << formatDiagnostics(found);
  EXPECT_NE(found[0].message.find("required input 'in' of module 'sink'"), std::string::npos);
  EXPECT_EQ(found[1].message,
            "instance 'p' (composite 'relay_pair') has no input 'input' "
            "(inputs: in)");
  EXPECT_EQ(found[1].loc.line, 8);
  EXPECT_EQ(found[2].message,
            "'p.in' is an input of instance 'p' (composite 'relay_pair'); a "
            "connection goes from an output to an input");
}

TEST(CompositeErrors, ConnectionInsideACompositeToAnUnknownNodeIsNamedInTheComposite) {
  const std::vector<Diagnostic> found = checkComposed(oneInstance(R"(
      <modules><module id="r" package="core" type="relay"/></modules>
      <connections><connection from="numbers.out" to="r.in"/></connections>)"));
  ASSERT_FALSE(found.empty());
  EXPECT_EQ(found[0].loc.line, 5);
  EXPECT_EQ(found[0].message,
            "no module, filter or instance 'numbers' in composite 'c' "
            "(known: r)");
}

TEST(CompositeErrors, BadExpressionIsReportedAtItsAttributeWithTheInstance) {
  const std::vector<Diagnostic> found = checkComposed(oneInstance(R"(
      <param name="n" default="2"/>
      <modules><repeat var="i" count="${n +}"><module id="r${i}" package="core" type="relay"/></repeat></modules>)"));
  EXPECT_ONLY_ERROR_AT(found, 5, 32,
                       "attribute 'count' of <repeat>: cannot evaluate '${n +}': an operand is "
                       "missing");
  EXPECT_EQ(found[0].loc.expandedFrom.size(), 1u);
}

TEST(CompositeErrors, ARepeatCountThatIsNotAnIntegerSuggestsWritingAnExpression) {
  EXPECT_ONLY_ERROR_AT(
      checkComposed(oneInstance(R"(<param name="n" default="2"/>
      <modules><repeat var="i" count="n"><module id="r${i}" package="core" type="relay"/></repeat></modules>)")),
      4, 32, "must be an integer, got 'n' (write ${...} to use a parameter or an expression)");
}

TEST(CompositeErrors, HugeRepeatCountIsRefusedQuicklyInsteadOfExpanded) {
  const std::vector<Diagnostic> found = checkComposed(oneInstance(R"(
      <connections><repeat var="i" count="${1000000 * 1000000}"/></connections>)"));
  EXPECT_ONLY_ERROR_AT(found, 4, 20, "the expansion makes more than 100000");
}

TEST(CompositeErrors, HugeAttributeTextIsRefusedBeforeMemoryRunsOut) {
  const std::string big(4000, 'x');
  const Result<Application> app = loadApplicationString(oneInstance(R"(
      <param name="big" default=")" + big + R"("/>
      <modules><repeat var="i" count="40000">
        <module id="m${i}" package="core" type="source"><param name="label" value="${big}"/></module>
      </repeat></modules>)"),
                                                        "app.xml");
  ASSERT_TRUE(app.ok()) << app.error().message;
  std::vector<Diagnostic> problems;
  const Result<Application> flat = expandComposites(*app, {}, &problems);
  ASSERT_TRUE(flat.ok());
  EXPECT_ONLY_ERROR_AT(problems, 6, 57, "the expansion makes more than 64 MiB of attribute text");
  EXPECT_LT(flat->modules.size(), 20000u);
}

TEST(CompositeErrors, AProblemRepeatedByEveryIterationIsReportedOnce) {
  const std::vector<Diagnostic> found = checkComposed(oneInstance(R"(
      <modules><repeat var="i" count="5000"><module id="m${j}" package="core" type="relay"/></repeat></modules>)"));
  EXPECT_ONLY_ERROR_AT(
      found, 4, 53, "attribute 'id' of <module>: unknown name 'j' in '${j}' (known: i, instance)");
}

TEST(CompositeErrors, IdsInsideACompositeMustNotHoldTheSeparator) {
  EXPECT_ONLY_ERROR_AT(checkComposed(oneInstance(R"(
      <modules><module id="a:b" package="core" type="relay"/></modules>)")),
                       4, 24, "id 'a:b' must not contain '.' or ':'");
}

TEST(CompositeErrors, RepeatVariableMayNotHideAParameter) {
  EXPECT_ONLY_ERROR_AT(checkComposed(oneInstance(R"(<param name="i" default="1"/>
      <modules><repeat var="i" count="2"><module id="r${i}" package="core" type="relay"/></repeat></modules>)")),
                       4, 24, "repeat variable 'i' hides a parameter");
}

// `instance` is the built-in ${instance} (the id of the instance being expanded): neither a
// parameter nor a repeat variable may take that name.
TEST(CompositeErrors, InstanceIsAReservedName) {
  EXPECT_ONLY_ERROR_AT(checkComposed(oneInstance(R"(<param name="instance" default="x"/>
      <modules><module id="r" package="core" type="relay"/></modules>)")),
                       3, 32,
                       "parameter name 'instance' is reserved: ${instance} is the id of the "
                       "instance being expanded; choose another name");
  EXPECT_ONLY_ERROR_AT(checkComposed(oneInstance(R"(
      <modules><repeat var="instance" count="2"><module id="r${instance}" package="core" type="relay"/></repeat></modules>)")),
                       4, 24, "repeat variable 'instance' is reserved");
}

TEST(CompositeErrors, StructuralProblemsOfACompositeAreFoundWhenLoading) {
  std::vector<Diagnostic> problems;
  const Result<Application> app = loadApplicationString(R"(<application>
  <composites>
    <composite name="bad name">
      <param name="2x"/>
      <param name="n" min="3" max="1"/>
      <param name="n"/>
      <connections/>
      <modules>
        <repeat var="i" cont="2"><module id="m" package="core" type="relay" hots="x"/></repeat>
      </modules>
    </composite>
  </composites>
</application>
)",
                                                        "app.xml", &problems);
  ASSERT_TRUE(app.ok());
  std::vector<std::string> messages;
  for (const Diagnostic& d : problems) {
    messages.push_back(std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + " " +
                       d.message);
  }
  EXPECT_EQ(
      messages,
      (std::vector<std::string>{
          "3:16 composite name 'bad name' may hold only letters, digits, '_' and '-' (its "
          "file is NAME.vrc.xml)",
          "4:14 parameter name '2x' must be a name: a letter or '_', then letters, digits, "
          "'_'",
          "5:31 max 1 is below min 3", "6:14 parameter 'n' is declared twice (first at line 5)",
          "8:7 <modules> is out of order (a composite's sections go: modules, instances, "
          "filters, connections)",
          "9:9 required attribute 'count' of <repeat> is missing or empty",
          "9:25 unknown attribute 'cont' on <repeat> (allowed: var, count, start); did you "
          "mean 'count'?",
          "9:77 unknown attribute 'hots' on <module> (allowed: id, package, type, host, endit); "
          "did you mean 'host'?"}));
}

TEST(CompositeErrors, NestedRepeatsAreBoundedByTheProductOfTheirCountsBeforeExpanding) {
  // 1000 x 1000 x 1000 iterations ran past 15 s although the expansion is capped at 100,000
  // items: the product is refused at the second repeat, before its first iteration.
  const std::vector<Diagnostic> found = checkComposed(oneInstance(R"(
      <connections><repeat var="i" count="1000"><repeat var="j" count="1000"><repeat var="k" count="1000"/></repeat></repeat></connections>)"));
  EXPECT_ONLY_ERROR_AT(found, 4, 49,
                       "repeat count 1000 times the counts of the repeats around it is refused "
                       "before expanding");
}

TEST(CompositeErrors, AFilterWithManyUnconnectedInputsIsOneProblemNotOnePerInput) {
  // 400 merges of 256 unconnected inputs made 102,400 problems at one source location, which
  // took minutes to sort and deduplicate (pairwise) and as many lines to print.
  const std::vector<Diagnostic> found = checkComposed(oneInstance(R"(
      <filters><repeat var="i" count="400"><filter id="m${i}" type="merge"><param name="inputs" value="256"/></filter></repeat></filters>)"));
  ASSERT_EQ(found.size(), 400u);
  EXPECT_EQ(found[0].message,
            "required inputs 'in0', 'in1', 'in2', 'in3' and 252 more of filter 'w:m0' (merge) are "
            "not connected");
}

}  // namespace
}  // namespace vrflow::app
