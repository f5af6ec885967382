#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "test_support.hpp"

namespace vrflow::app {
namespace {

bool haveXmllint() {
  return std::system("xmllint --version >/dev/null 2>&1") == 0;
}

// Runs xmllint --schema; true when the file is valid.
bool validAgainst(const std::string& schema, const std::string& file) {
  const std::string command =
      "xmllint --noout --schema '" + schema + "' '" + file + "' >/dev/null 2>&1";
  return std::system(command.c_str()) == 0;
}

std::string schemaPath(const char* name) {
  return testing::sourceDir() + "/runtime/schema/" + name;
}

TEST(Schema, EveryValidApplicationFileMatchesTheApplicationSchema) {
  if (!haveXmllint()) GTEST_SKIP() << "xmllint is not installed";
  int checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(testing::dataDir())) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("valid", 0) != 0 || entry.path().extension() != ".xml") continue;
    EXPECT_TRUE(validAgainst(schemaPath("vrflow-application.xsd"), entry.path().string())) << name;
    ++checked;
  }
  EXPECT_GE(checked, 4);
}

TEST(Schema, RejectsAnApplicationWithAnUnknownAttribute) {
  if (!haveXmllint()) GTEST_SKIP() << "xmllint is not installed";
  EXPECT_FALSE(validAgainst(schemaPath("vrflow-application.xsd"),
                            testing::dataDir() + "/invalid_unknown_attribute.xml"));
}

TEST(Schema, EveryTestManifestMatchesThePackageSchema) {
  if (!haveXmllint()) GTEST_SKIP() << "xmllint is not installed";
  for (const char* package : {"core", "physics"}) {
    EXPECT_TRUE(validAgainst(schemaPath("vrflow-package.xsd"),
                             testing::dataDir() + "/packages/" + package + "/vrflow-package.xml"))
        << package;
  }
}

// The manifests that ship with vrflow, with their file parameters' `access`, match the schema.
TEST(Schema, EveryShippedManifestMatchesThePackageSchema) {
  if (!haveXmllint()) GTEST_SKIP() << "xmllint is not installed";
  for (const char* folder :
       {"runtime/modules/core", "nodes/fluid", "nodes/massspring", "nodes/rigid", "nodes/viewer"}) {
    EXPECT_TRUE(validAgainst(schemaPath("vrflow-package.xsd"),
                             testing::sourceDir() + "/" + folder + "/vrflow-package.xml"))
        << folder;
  }
}

}  // namespace
}  // namespace vrflow::app
