// Expansion of composites: prefixes, exposed ports, nesting, parameters and <repeat>.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "composite_support.hpp"
#include "test_support.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/validate.hpp"

namespace vrflow::app {
namespace {

using testing::connectionTexts;
using testing::expandOrFail;
using testing::nodeIds;
using Strings = std::vector<std::string>;

constexpr std::string_view kPairApp = R"(<application>
  <composites>
    <composite name="pair">
      <input name="in" to="a.in"/>
      <output name="out" from="b.out"/>
      <modules>
        <module id="a" package="core" type="relay"/>
        <module id="b" package="core" type="relay"/>
      </modules>
      <connections>
        <connection from="a.out" to="b.in"/>
      </connections>
    </composite>
  </composites>
  <modules>
    <module id="numbers" package="core" type="source"/>
    <module id="sink" package="core" type="sink"/>
  </modules>
  <instances>
    <instance id="p" composite="pair"/>
    <instance id="q" composite="pair"/>
  </instances>
  <connections>
    <connection from="numbers.out" to="p.in"/>
    <connection from="p.out" to="q.in" capacity="3"/>
    <connection from="q.out" to="sink.in"/>
  </connections>
  <editor>
    <node ref="p" x="5"/>
    <node ref="sink" x="9"/>
  </editor>
</application>
)";

TEST(CompositeExpansion, EachInstancePrefixesTheIdsInsideItWithItsIdAndAColon) {
  const Application flat = expandOrFail(kPairApp);
  EXPECT_EQ(nodeIds(flat), (Strings{"numbers", "sink", "p:a", "p:b", "q:a", "q:b"}));
  EXPECT_TRUE(flat.instances.empty());
  EXPECT_TRUE(flat.composites.empty());
  EXPECT_TRUE(validate(flat, testing::testCatalog()).empty())
      << formatDiagnostics(validate(flat, testing::testCatalog()));
}

TEST(CompositeExpansion, ConnectionsToExposedPortsGoToTheInnerPortsTheyStandFor) {
  const Application flat = expandOrFail(kPairApp);
  EXPECT_EQ(connectionTexts(flat),
            (Strings{"numbers.out -> p:a.in", "p:b.out -> q:a.in", "q:b.out -> sink.in",
                     "p:a.out -> p:b.in", "q:a.out -> q:b.in"}));
  EXPECT_EQ(flat.connections[1].capacity, 3);  // the outer connection's settings are kept
}

TEST(CompositeExpansion, EditorPositionsOfInstancesAreDroppedAndOthersKept) {
  const Application flat = expandOrFail(kPairApp);
  ASSERT_EQ(flat.editor.size(), 1u);
  EXPECT_EQ(flat.editor[0].ref, "sink");
}

TEST(CompositeExpansion, InnerElementsKeepTheCompositeLocationAndTheInstanceThatMadeThem) {
  const Application flat = expandOrFail(kPairApp);
  const Module* inner = findModule(flat, "q:b");
  ASSERT_NE(inner, nullptr);
  EXPECT_EQ(inner->loc.line, 8);
  ASSERT_EQ(inner->loc.expandedFrom.size(), 1u);
  EXPECT_EQ(inner->loc.expandedFrom[0], (InstanceSite{"q", "pair", "app.xml", 21, 5}));
  EXPECT_TRUE(findModule(flat, "numbers")->loc.expandedFrom.empty());
}

TEST(CompositeExpansion, NestedCompositesPrefixEveryLevelAndResolvePortsThroughEachLevel) {
  const Application flat = expandOrFail(R"(<application>
  <composites>
    <composite name="quad">
      <input name="in" to="x.in"/>
      <output name="out" from="y.out"/>
      <instances>
        <instance id="x" composite="relay_pair"/>
        <instance id="y" composite="relay_pair"/>
      </instances>
      <connections>
        <connection from="x.out" to="y.in"/>
      </connections>
    </composite>
  </composites>
  <modules>
    <module id="numbers" package="core" type="source"/>
    <module id="sink" package="core" type="sink"/>
  </modules>
  <instances>
    <instance id="q" composite="quad"/>
  </instances>
  <connections>
    <connection from="numbers.out" to="q.in"/>
    <connection from="q.out" to="sink.in"/>
  </connections>
</application>
)");
  EXPECT_EQ(nodeIds(flat),
            (Strings{"numbers", "sink", "q:x:first", "q:x:second", "q:y:first", "q:y:second"}));
  EXPECT_EQ(connectionTexts(flat),
            (Strings{"numbers.out -> q:x:first.in", "q:y:second.out -> sink.in",
                     "q:x:second.out -> q:y:first.in", "q:x:first.out -> q:x:second.in",
                     "q:y:first.out -> q:y:second.in"}));
  const Module* deepest = findModule(flat, "q:y:second");
  ASSERT_NE(deepest, nullptr);
  ASSERT_EQ(deepest->loc.expandedFrom.size(), 2u);  // innermost first
  EXPECT_EQ(deepest->loc.expandedFrom[0].instance, "q:y");
  EXPECT_EQ(deepest->loc.expandedFrom[0].composite, "relay_pair");
  EXPECT_EQ(deepest->loc.expandedFrom[1].instance, "q");
  EXPECT_EQ(deepest->loc.file, testing::compositeDir() + "/relay_pair.vrc.xml");
}

// ${instance} is the full id of the instance being expanded: unique per instance at every
// level, which is what an MPI job name needs (one job per instance of a parallel module).
TEST(CompositeExpansion, InstanceIsTheFullIdOfTheInstanceBeingExpanded) {
  const Application flat = expandOrFail(R"(<application>
  <composites>
    <composite name="block">
      <param name="tag" default="none"/>
      <modules>
        <module id="s" package="core" type="source">
          <param name="label" value="${instance}/${tag}"/>
        </module>
      </modules>
    </composite>
    <composite name="outer">
      <modules>
        <module id="own" package="core" type="source"><param name="label" value="${instance}"/></module>
      </modules>
      <instances>
        <instance id="water" composite="block"><param name="tag" value="${instance}"/></instance>
      </instances>
    </composite>
  </composites>
  <instances>
    <instance id="water" composite="block"/>
    <instance id="o" composite="outer"/>
    <instance id="p" composite="outer"/>
  </instances>
</application>
)");
  std::map<std::string, std::string> labels;
  for (const Module& module : flat.modules) {
    labels[module.id] = paramString(module.params, "label", "?");
  }
  EXPECT_EQ(labels, (std::map<std::string, std::string>{{"water:s", "water/none"},
                                                        {"o:own", "o"},
                                                        {"o:water:s", "o:water/o"},
                                                        {"p:own", "p"},
                                                        {"p:water:s", "p:water/p"}}));
}

TEST(CompositeExpansion, NodesWithoutAHostRunOnTheHostOfTheirInstance) {
  const Application flat =
      expandOrFail(testing::readFile(testing::compositeDir() + "/composites_in_file.xml"));
  EXPECT_EQ(findModule(flat, "c:s0:r")->host, "right");
  EXPECT_EQ(findModule(flat, "numbers")->host, "left");
  const Module* label = findModule(flat, "c:s1:r");
  ASSERT_NE(label, nullptr);
  EXPECT_EQ(connectionTexts(flat).back(), "c:s0:r.out -> c:s1:r.in");
  EXPECT_EQ(flat.connections.back().policy, QueuePolicy::DropOldest);
}

// The workers composite: n relay pairs behind a broadcast, merged by a binary tree of 2-input
// merge filters laid out as a heap (filter k takes filters 2k and 2k+1, workers are the leaves
// n..2n-1).
Application farmOf(int n) {
  Result<Application> app = loadApplicationFile(testing::compositeDir() + "/workers_app.xml");
  EXPECT_TRUE(app.ok()) << app.error().message;
  app->instances[0].params[0].value = std::to_string(n);
  Result<Application> flat = expandComposites(*app, testing::testCompositeSources());
  EXPECT_TRUE(flat.ok()) << flat.error().message;
  return std::move(flat).value();
}

TEST(CompositeExpansion, RepeatCountFromAParameterMakesNWorkersAndABalancedMergeTree) {
  for (int n = 2; n <= 9; ++n) {
    SCOPED_TRACE("n = " + std::to_string(n));
    const Application flat = farmOf(n);
    EXPECT_TRUE(validate(flat, testing::testCatalog()).empty())
        << formatDiagnostics(validate(flat, testing::testCatalog()));
    EXPECT_EQ(flat.modules.size(), 2u + 2u * static_cast<std::size_t>(n));
    EXPECT_EQ(flat.filters.size(), static_cast<std::size_t>(n));  // fan + n-1 merges
    // Where each node's output goes; each merge input is fed exactly once.
    std::map<std::string, std::string> parentOf;
    std::map<std::string, int> feeds;
    for (const Connection& c : flat.connections) {
      if (c.to.node.rfind("farm:merge", 0) != 0) continue;
      ++feeds[toString(c.to)];
      EXPECT_TRUE(parentOf.emplace(c.from.node, c.to.node).second) << c.from.node;
    }
    EXPECT_EQ(feeds.size(), 2u * static_cast<std::size_t>(n - 1));
    for (const auto& [input, count] : feeds) EXPECT_EQ(count, 1) << input;
    int shallowest = 1 << 20;
    int deepest = 0;
    for (int i = 0; i < n; ++i) {
      std::string node = "farm:w" + std::to_string(i) + ":second";
      int depth = 0;
      while (parentOf.count(node) != 0 && depth <= n) {
        node = parentOf[node];
        ++depth;
      }
      EXPECT_EQ(node, "farm:merge1") << "worker " << i << " does not reach the root";
      shallowest = std::min(shallowest, depth);
      deepest = std::max(deepest, depth);
    }
    EXPECT_EQ(deepest, static_cast<int>(std::ceil(std::log2(n))));
    EXPECT_LE(deepest - shallowest, 1);
    EXPECT_EQ(connectionTexts(flat)[1], "farm:merge1.out -> sink.in");
  }
}

TEST(CompositeExpansion, FiveWorkersMakeExactlyThisNetwork) {
  const Application flat = farmOf(5);
  EXPECT_EQ(connectionTexts(flat), (Strings{"numbers.out -> farm:fan.in",
                                            "farm:merge1.out -> sink.in",
                                            "farm:fan.out -> farm:w0:first.in",
                                            "farm:w0:second.out -> farm:merge2.in1",
                                            "farm:fan.out -> farm:w1:first.in",
                                            "farm:w1:second.out -> farm:merge3.in0",
                                            "farm:fan.out -> farm:w2:first.in",
                                            "farm:w2:second.out -> farm:merge3.in1",
                                            "farm:fan.out -> farm:w3:first.in",
                                            "farm:w3:second.out -> farm:merge4.in0",
                                            "farm:fan.out -> farm:w4:first.in",
                                            "farm:w4:second.out -> farm:merge4.in1",
                                            "farm:merge2.out -> farm:merge1.in0",
                                            "farm:merge3.out -> farm:merge1.in1",
                                            "farm:merge4.out -> farm:merge2.in0",
                                            "farm:w0:first.out -> farm:w0:second.in",
                                            "farm:w1:first.out -> farm:w1:second.in",
                                            "farm:w2:first.out -> farm:w2:second.in",
                                            "farm:w3:first.out -> farm:w3:second.in",
                                            "farm:w4:first.out -> farm:w4:second.in"}));
  EXPECT_EQ(flat.connections[2].capacity, 8);  // ${capacity}: a parameter's default
}

// Expands `value` as the label of a module inside a composite with x = 7, word = hello.
Result<std::string> substituted(const std::string& value) {
  std::string attribute;
  for (const char c : value) attribute += c == '"' ? std::string("&quot;") : std::string(1, c);
  const std::string xml = R"(<application><composites><composite name="calc">
    <param name="x" default="7"/><param name="word" default="hello"/>
    <modules><module id="m" package="core" type="source">
      <param name="label" value=")" +
                          attribute + R"("/></module></modules>
    </composite></composites>
    <instances><instance id="c" composite="calc"/></instances></application>)";
  Result<Application> app = loadApplicationString(xml, "app.xml");
  if (!app) return app.error();
  Result<Application> flat = expandComposites(*app, {});
  if (!flat) return flat.error();
  return flat->modules.at(0).params.at(0).value;
}

TEST(CompositeExpansion, SubstitutionFollowsTheDocumentedGrammar) {
  const std::vector<std::pair<std::string, std::string>> cases = {{"${x}", "7"},
                                                                  {"${ x }", "7"},
                                                                  {"${word}", "hello"},
                                                                  {"${x + 1}", "8"},
                                                                  {"${x*2+1}", "15"},
                                                                  {"${(x + 1) * 2}", "16"},
                                                                  {"${x / 2}", "3"},
                                                                  {"${x % 4}", "3"},
                                                                  {"${-x / 2}", "-3"},
                                                                  {"${-x % 4}", "-3"},
                                                                  {"${x - -1}", "8"},
                                                                  {"a${x}b${x - 7}c", "a7b0c"},
                                                                  {"$$x", "$x"},
                                                                  {"$${x}", "${x}"},
                                                                  {"cost $5 $", "cost $5 $"},
                                                                  {"${3 * (2 + (x))}", "27"}};
  for (const auto& [written, expected] : cases) {
    const Result<std::string> value = substituted(written);
    ASSERT_TRUE(value.ok()) << written << ": " << value.error().message;
    EXPECT_EQ(*value, expected) << written;
  }
}

TEST(CompositeExpansion, SubstitutionErrorsSayWhatIsWrong) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"${x +}", "an operand is missing"},
      {"${y}", "unknown name 'y' in '${y}' (known: instance, word, x)"},
      {"${y + 1}", "unknown name 'y'"},
      {"${word + 1}", "'word' is 'hello', not an integer"},
      {"${x / (x - 7)}", "division by zero"},
      {"${x", "'${' without a closing '}'"},
      {"${9223372036854775807 + x}", "does not fit in 64 bits"},
      {"${x x}", "unexpected 'x'"},
      {"${(x}", "missing ')'"}};
  for (const auto& [written, expected] : cases) {
    const Result<std::string> value = substituted(written);
    ASSERT_FALSE(value.ok()) << written << " gave " << *value;
    EXPECT_NE(value.error().message.find(expected), std::string::npos)
        << written << ": " << value.error().message;
  }
}

TEST(CompositeExpansion, ApplicationWithoutInstancesExpandsToItself) {
  const std::string original = testing::readFile(testing::dataDir() + "/valid_pipeline.xml");
  const Result<Application> app = loadApplicationString(original, "valid_pipeline.xml");
  ASSERT_TRUE(app.ok());
  const Result<Application> flat = expandComposites(*app, {});
  ASSERT_TRUE(flat.ok()) << flat.error().message;
  EXPECT_EQ(nodeIds(*flat), nodeIds(*app));
  EXPECT_EQ(connectionTexts(*flat), connectionTexts(*app));
}

TEST(CompositeExpansion, DefaultSourcesSearchTheApplicationsFolderThenTheEnvironmentThenPackages) {
  Application app;
  app.file = "/some/where/app.xml";
  ::setenv("VRFLOW_COMPOSITE_PATH", "/a::/b", 1);
  const CompositeSources sources = defaultCompositeSources(app, {"/extra"});
  ::unsetenv("VRFLOW_COMPOSITE_PATH");
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  const std::string share =
      (std::filesystem::path(self).parent_path().parent_path() / "share/vrflow/composites")
          .string();
  EXPECT_EQ(sources.searchPath, (Strings{"/some/where", "/extra", "/a", "/b", share}));
}

TEST(CompositeExpansion, ValidateExpandsAnApplicationFileThatUsesComposites) {
  const std::vector<Diagnostic> found =
      checkApplicationFile(testing::compositeDir() + "/workers_app.xml", testing::testCatalog());
  EXPECT_TRUE(found.empty()) << formatDiagnostics(found);
}

}  // namespace
}  // namespace vrflow::app
