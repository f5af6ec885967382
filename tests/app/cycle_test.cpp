#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vrflow/app/validate.hpp"

namespace vrflow::app {
namespace {

using testing::check;

TEST(CycleCheck, CycleWithoutInitialMessageIsNamedAtItsFirstConnection) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <modules>
    <module id="anim" package="physics" type="animator"/>
    <module id="inter" package="physics" type="interactor"/>
  </modules>
  <connections>
    <connection from="anim.objects" to="inter.objects"/>
    <connection from="inter.forces" to="anim.events"/>
  </connections>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 7, 5,
                       "cycle without initial message (would deadlock): anim.objects -> "
                       "inter.objects, inter.forces -> anim.events");
}

TEST(CycleCheck, InitialMessageOnAModuleInputOfTheCycleStartsIt) {
  EXPECT_TRUE(check(R"(<application>
  <modules>
    <module id="anim" package="physics" type="animator">
      <input port="events" initial-messages="1"/>
    </module>
    <module id="inter" package="physics" type="interactor"/>
  </modules>
  <connections>
    <connection from="anim.objects" to="inter.objects"/>
    <connection from="inter.forces" to="anim.events"/>
  </connections>
</application>
)")
                  .empty());
}

TEST(CycleCheck, InitialMessagesOnAnInputOutsideTheCycleDoNotStartIt) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <modules>
    <module id="a" package="core" type="relay">
      <input port="beginIt" initial-messages="1"/>
    </module>
    <module id="b" package="core" type="relay"/>
  </modules>
  <connections>
    <connection from="b.out" to="a.in"/>
    <connection from="a.out" to="b.in"/>
  </connections>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 9, 5, "b.out -> a.in, a.out -> b.in");
}

TEST(CycleCheck, InitialFilterWithAPositiveCountStartsTheCycle) {
  EXPECT_TRUE(check(R"(<application>
  <modules>
    <module id="anim" package="physics" type="animator"/>
    <module id="inter" package="physics" type="interactor"/>
  </modules>
  <filters>
    <filter id="pre" type="initial"/>
  </filters>
  <connections>
    <connection from="anim.objects" to="inter.objects"/>
    <connection from="inter.forces" to="pre.in"/>
    <connection from="pre.out" to="anim.events"/>
  </connections>
</application>
)")
                  .empty());
}

TEST(CycleCheck, InitialFilterWithCountZeroDoesNotStartTheCycle) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <modules>
    <module id="anim" package="physics" type="animator"/>
    <module id="inter" package="physics" type="interactor"/>
  </modules>
  <filters>
    <filter id="pre" type="initial">
      <param name="count" value="0"/>
    </filter>
  </filters>
  <connections>
    <connection from="anim.objects" to="inter.objects"/>
    <connection from="inter.forces" to="pre.in"/>
    <connection from="pre.out" to="anim.events"/>
  </connections>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 12, 5,
                       "anim.objects -> inter.objects, inter.forces -> pre.in, pre.out -> "
                       "anim.events");
}

TEST(CycleCheck, BeginItPacingNeedsAnInitialMessage) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <modules>
    <module id="src" package="core" type="source"/>
    <module id="sink" package="core" type="sink"/>
  </modules>
  <connections>
    <connection from="src.out" to="sink.in"/>
    <connection from="sink.endIt" to="src.beginIt"/>
  </connections>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 7, 5, "src.out -> sink.in, sink.endIt -> src.beginIt");
}

TEST(CycleCheck, ModuleFeedingItselfIsACycle) {
  EXPECT_ONLY_ERROR_AT(check(R"(<application>
  <modules>
    <module id="a" package="core" type="relay"/>
  </modules>
  <connections>
    <connection from="a.out" to="a.in"/>
  </connections>
</application>
)"),
                       6, 5, "cycle without initial message (would deadlock): a.out -> a.in;");
}

TEST(CycleCheck, EachSeparateCycleIsReportedOnce) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <modules>
    <module id="a" package="core" type="relay"/>
    <module id="b" package="core" type="relay"/>
    <module id="c" package="core" type="relay"/>
    <module id="d" package="core" type="relay"/>
  </modules>
  <connections>
    <connection from="a.out" to="b.in"/>
    <connection from="c.out" to="d.in"/>
    <connection from="b.out" to="a.in"/>
    <connection from="b.out" to="a.beginIt"/>
    <connection from="d.out" to="c.in"/>
  </connections>
</application>
)");
  ASSERT_EQ(found.size(), 2u) << formatDiagnostics(found);
  EXPECT_EQ(found[0].loc.line, 9);
  EXPECT_NE(found[0].message.find("a.out -> b.in, b.out -> a.in;"), std::string::npos);
  EXPECT_EQ(found[1].loc.line, 10);
  EXPECT_NE(found[1].message.find("c.out -> d.in, d.out -> c.in;"), std::string::npos);
}

TEST(CycleCheck, CycleThroughTwentyThousandModulesIsFound) {
  Application app;
  const int length = 20000;
  for (int i = 0; i < length; ++i) {
    Module relay;
    relay.id = "m" + std::to_string(i);
    relay.package = "core";
    relay.type = "relay";
    app.modules.push_back(relay);
    Connection next;
    next.from = {relay.id, "out"};
    next.to = {"m" + std::to_string((i + 1) % length), "in"};
    app.connections.push_back(next);
  }
  app.modules[0].inputs.push_back(InputConfig{"in", 1, InputMode::Fifo, {}});
  EXPECT_TRUE(validate(app, testing::testCatalog()).empty());
  app.modules[0].inputs.clear();
  const std::vector<Diagnostic> found = validate(app, testing::testCatalog());
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NE(found[0].message.find("m0.out -> m1.in, m1.out -> m2.in"), std::string::npos);
}

}  // namespace
}  // namespace vrflow::app
