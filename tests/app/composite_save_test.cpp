// Saving applications that use composites, and composite files: the usage is kept, not the
// expansion, byte for byte.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "composite_support.hpp"
#include "test_support.hpp"
#include "vrflow/app/composite_file.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/writer.hpp"

namespace vrflow::app {
namespace {

std::vector<std::string> filesEndingWith(const std::string& suffix) {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(testing::compositeDir())) {
    const std::string path = entry.path().string();
    if (path.size() > suffix.size() && path.ends_with(suffix)) files.push_back(path);
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(CompositeSave, LoadThenSaveKeepsEveryApplicationUsingCompositesByteForByte) {
  const std::vector<std::string> files = filesEndingWith("_app.xml");
  std::vector<std::string> all = files;
  all.push_back(testing::compositeDir() + "/composites_in_file.xml");
  ASSERT_GE(all.size(), 3u);
  for (const std::string& file : all) {
    const std::string original = testing::readFile(file);
    const Result<Application> app = loadApplicationString(original, file);
    ASSERT_TRUE(app.ok()) << app.error().message;
    EXPECT_EQ(saveApplication(*app), original) << file;
  }
}

TEST(CompositeSave, LoadThenSaveKeepsEveryCompositeFileByteForByte) {
  const std::vector<std::string> files = filesEndingWith(".vrc.xml");
  ASSERT_GE(files.size(), 4u);
  for (const std::string& file : files) {
    const std::string original = testing::readFile(file);
    const Result<Composite> composite = loadCompositeString(original, file);
    ASSERT_TRUE(composite.ok()) << composite.error().message;
    EXPECT_EQ(saveComposite(*composite), original) << file;
  }
}

TEST(CompositeSave, SavedApplicationKeepsTheTemplateNotItsExpansion) {
  const Result<Application> app =
      loadApplicationFile(testing::compositeDir() + "/composites_in_file.xml");
  ASSERT_TRUE(app.ok()) << app.error().message;
  ASSERT_EQ(app->composites.size(), 2u);
  EXPECT_EQ(app->instances.size(), 1u);
  const std::string saved = saveApplication(*app);
  EXPECT_NE(saved.find(R"(<repeat var="i" count="${length - 1}">)"), std::string::npos);
  EXPECT_NE(saved.find(R"(<connection from="numbers.out" to="c.in"/>)"), std::string::npos);
  EXPECT_EQ(saved.find("c:s0"), std::string::npos);
}

TEST(CompositeSave, HandWrittenCompositeIsRewrittenInCanonicalFormOnceThenStable) {
  const std::string handWritten = R"(<composite doc="d" name="x">
  <connections><connection policy="block" to="b.in" from="a.out"/></connections>
  <output from="a.out" name="out"/>
  <param max="9" name="n" min="+1"/>
</composite>)";
  std::vector<Diagnostic> problems;
  const Result<Composite> first = loadCompositeString(handWritten, "x.vrc.xml", &problems);
  ASSERT_TRUE(first.ok());
  ASSERT_EQ(problems.size(), 1u);  // "+1" is not an integer
  const std::string saved = saveComposite(*first);
  EXPECT_EQ(saved, R"(<?xml version="1.0" encoding="UTF-8"?>
<composite name="x" version="1" doc="d">
  <param name="n" max="9"/>
  <output name="out" from="a.out"/>
  <connections>
    <connection from="a.out" to="b.in" policy="block"/>
  </connections>
</composite>
)");
  const Result<Composite> second = loadCompositeString(saved, "x.vrc.xml");
  ASSERT_TRUE(second.ok()) << second.error().message;
  EXPECT_EQ(saveComposite(*second), saved);
}

TEST(CompositeSave, ExpandedApplicationSavesAndLoadsAsAFlatApplication) {
  const Application flat =
      testing::expandOrFail(testing::readFile(testing::compositeDir() + "/workers_app.xml"));
  const std::string saved = saveApplication(flat);
  const Result<Application> again = loadApplicationString(saved, "flat.xml");
  ASSERT_TRUE(again.ok()) << again.error().message;
  EXPECT_TRUE(again->instances.empty());
  EXPECT_EQ(testing::nodeIds(*again), testing::nodeIds(flat));
  EXPECT_EQ(saveApplication(*again), saved);
}

bool haveXmllint() {
  return std::system("xmllint --version >/dev/null 2>&1") == 0;
}

bool validAgainst(const std::string& schema, const std::string& file) {
  const std::string command = "xmllint --noout --schema '" + testing::sourceDir() +
                              "/runtime/schema/" + schema + "' '" + file + "' >/dev/null 2>&1";
  return std::system(command.c_str()) == 0;
}

TEST(CompositeSave, CompositeFilesAndApplicationsUsingThemMatchTheSchemas) {
  if (!haveXmllint()) GTEST_SKIP() << "xmllint is not installed";
  for (const std::string& file : filesEndingWith(".vrc.xml")) {
    EXPECT_TRUE(validAgainst("vrflow-composite.xsd", file)) << file;
  }
  for (const std::string& file : filesEndingWith(".xml")) {
    if (file.ends_with(".vrc.xml")) continue;
    EXPECT_TRUE(validAgainst("vrflow-application.xsd", file)) << file;
  }
}

}  // namespace
}  // namespace vrflow::app
