#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vrflow/app/catalog.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/writer.hpp"

namespace vrflow::app {
namespace {

constexpr std::string_view kTwoFolders = R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="a" version="1">
  <packages path="."/>
  <packages path="../shared/packages"/>
  <packages path="/opt/vrflow/packages"/>
  <modules>
    <module id="m" package="core" type="source"/>
  </modules>
</application>
)";

TEST(PackageFolders, AreReadInOrderAndSavedBackByteForByte) {
  const Result<Application> app = loadApplicationString(kTwoFolders, "/work/apps/app.xml");
  ASSERT_TRUE(app.ok()) << app.error().message;
  ASSERT_EQ(app->packages.size(), 3u);
  EXPECT_EQ(app->packages[1].path, "../shared/packages");
  EXPECT_EQ(app->packages[1].loc.line, 4);
  EXPECT_EQ(saveApplication(*app), kTwoFolders);
}

TEST(PackageFolders, RelativePathsAreTakenFromTheFilesFolder) {
  const Result<Application> app = loadApplicationString(kTwoFolders, "/work/apps/app.xml");
  ASSERT_TRUE(app.ok()) << app.error().message;
  EXPECT_EQ(packageFolderPath(*app, app->packages[0]), "/work/apps/");
  EXPECT_EQ(packageFolderPath(*app, app->packages[1]), "/work/shared/packages");
  EXPECT_EQ(packageFolderPath(*app, app->packages[2]), "/opt/vrflow/packages");
}

TEST(PackageFolders, MissingFolderIsReportedAtItsPathAttribute) {
  const Result<Application> app = loadApplicationString(kTwoFolders, "/nonexistent/apps/app.xml");
  ASSERT_TRUE(app.ok()) << app.error().message;
  std::vector<Diagnostic> problems;
  EXPECT_TRUE(packageFolders(*app, problems).empty());
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_EQ(formatDiagnostic(problems[1]),
            "/nonexistent/apps/app.xml:4:13: error: package folder '../shared/packages' "
            "(/nonexistent/shared/packages) is not a folder; <packages path> is taken from the "
            "application file's folder");
}

TEST(PackageFolders, ExistingFolderIsKeptResolved) {
  Application app;
  app.file = testing::dataDir() + "/app.xml";
  app.packages.push_back({"packages", {}});
  std::vector<Diagnostic> problems;
  EXPECT_EQ(packageFolders(app, problems),
            (std::vector<std::string>{testing::dataDir() + "/packages"}));
  EXPECT_TRUE(problems.empty());
}

TEST(PackageFolders, MustComeBeforeEveryOtherSectionAndNameAPath) {
  std::vector<Diagnostic> late;
  (void)loadApplicationString(R"(<application version="1">
  <hosts><host id="h"/></hosts>
  <packages path="."/>
</application>)",
                              "app.xml", &late);
  ASSERT_FALSE(late.empty());
  EXPECT_NE(late[0].message.find("<packages> is out of order (sections go: packages, hosts"),
            std::string::npos)
      << formatDiagnostics(late);
  std::vector<Diagnostic> noPath;
  (void)loadApplicationString("<application version=\"1\"><packages/></application>", "app.xml",
                              &noPath);
  ASSERT_FALSE(noPath.empty());
  EXPECT_NE(noPath[0].message.find("path"), std::string::npos) << formatDiagnostics(noPath);
}

TEST(PackageFolders, SearchPathReportsAHiddenPackageButNotACopy) {
  const std::string packages = testing::dataDir() + "/packages";
  Catalog copies;
  ASSERT_TRUE(copies.loadSearchPath({packages, packages + "/../packages/core"}).ok());
  EXPECT_TRUE(copies.hiddenPackages().empty());
  Catalog catalog;
  ASSERT_TRUE(
      catalog
          .addPackageString(R"(<package name="core"><module type="x" executable="y"/></package>)",
                            "/elsewhere/core/vrflow-package.xml")
          .ok());
  ASSERT_TRUE(catalog.loadSearchPath({packages}).ok());
  // addPackageString() records the name, so the search path leaves core out silently only
  // when the manifests are the same; here they are not.
  ASSERT_EQ(catalog.hiddenPackages().size(), 1u);
  EXPECT_EQ(catalog.hiddenPackages()[0].package, "core");
  const std::vector<Diagnostic> warnings = hiddenPackageWarnings(catalog);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].severity, Diagnostic::Warning);
}

}  // namespace
}  // namespace vrflow::app
