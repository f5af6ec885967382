// `<packages path="..."/>` end to end through `vrflow validate`: folders taken from the
// application file's folder whatever the working folder, a missing folder reported at its line,
// and which of two packages of the same name is used.
#include <gtest/gtest.h>

#include <filesystem>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

CommandResult vrflowIn(const std::string& folder, const std::string& arguments) {
  return runCommand({"/bin/sh", "-c", "cd " + folder + " && " + binDir() + "/vrflow " + arguments});
}

// A package `pkg` with one module type, run by the core source's program.
void writePackage(const TempDir& dir, const std::string& folder, const std::string& type) {
  std::filesystem::create_directories(dir.file(folder + "/pkg"));
  dir.write(folder + "/pkg/vrflow-package.xml", "<package name=\"pkg\">\n  <module type=\"" + type +
                                                    "\" executable=\"vrflow-core-source\"/>\n"
                                                    "</package>\n");
}

std::string appUsing(const std::string& packagesPath, const std::string& type) {
  return "<application name=\"a\" version=\"1\">\n  <packages path=\"" + packagesPath +
         "\"/>\n  <modules>\n    <module id=\"m\" package=\"pkg\" type=\"" + type +
         "\"/>\n  </modules>\n</application>\n";
}

TEST(PackageFolders, RelativeFolderIsTakenFromTheApplicationFileNotTheWorkingFolder) {
  TempDir dir;
  writePackage(dir, "apps/mine", "gen");
  std::filesystem::create_directories(dir.file("elsewhere"));
  dir.write("apps/app.xml", appUsing("mine", "gen"));
  const auto ran = vrflowIn(dir.file("elsewhere"), "validate ../apps/app.xml");
  EXPECT_EQ(ran.exitCode, 0) << ran.err;
  EXPECT_EQ(ran.err, "");
  // Without the element the package is unknown: the folder is what made it known.
  dir.write("apps/bare.xml",
            "<application name=\"a\" version=\"1\">\n  <modules>\n    <module "
            "id=\"m\" package=\"pkg\" type=\"gen\"/>\n  </modules>\n"
            "</application>\n");
  EXPECT_NE(vrflowIn(dir.file("elsewhere"), "validate ../apps/bare.xml").exitCode, 0);
}

TEST(PackageFolders, MissingFolderIsAnErrorAtItsLineNamingTheResolvedPath) {
  TempDir dir;
  dir.write("app.xml", appUsing("no-such-folder", "gen"));
  const auto ran = vrflowIn(dir.path(), "validate app.xml");
  EXPECT_NE(ran.exitCode, 0);
  EXPECT_NE(ran.err.find("app.xml:2:13: error: package folder 'no-such-folder' (" +
                         dir.file("no-such-folder") + ") is not a folder"),
            std::string::npos)
      << ran.err;
  const auto run = vrflowIn(dir.path(), "run app.xml -n 1");
  EXPECT_NE(run.exitCode, 0);
  EXPECT_NE(run.err.find("app.xml:2:13: error: package folder"), std::string::npos) << run.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

// `vrflow --packages cli validate app.xml`, package `pkg` declaring `cliType` in cli/ and
// `fileType` in file/ (the file's <packages>), the file using `pkg/cliType`.
CommandResult validateWithTwoPackages(const TempDir& dir, const std::string& cliType,
                                      const std::string& fileType) {
  writePackage(dir, "cli", cliType);
  writePackage(dir, "file", fileType);
  dir.write("app.xml", appUsing("file", cliType));
  return vrflowIn(dir.path(), "--packages cli validate app.xml");
}

TEST(PackageFolders, CommandLineFolderComesFirstAndTheHiddenPackageIsReported) {
  TempDir dir;
  const auto ran = validateWithTwoPackages(dir, "from-cli", "from-file");
  EXPECT_EQ(ran.exitCode, 0) << ran.err;
  EXPECT_NE(ran.err.find(
                dir.file("file/pkg/vrflow-package.xml") + ": warning: package 'pkg' is not used: " +
                dir.file("cli/pkg/vrflow-package.xml") + " comes first on the search path"),
            std::string::npos)
      << ran.err;
  // The file's own package is the one used without --packages.
  dir.write("own.xml", appUsing("file", "from-file"));
  const auto own = vrflowIn(dir.path(), "validate own.xml");
  EXPECT_EQ(own.exitCode, 0) << own.err;
  EXPECT_EQ(own.err, "");
}

TEST(PackageFolders, IdenticalCopyOfAPackageIsNotReported) {
  TempDir dir;
  const auto ran = validateWithTwoPackages(dir, "gen", "gen");
  EXPECT_EQ(ran.exitCode, 0) << ran.err;
  EXPECT_EQ(ran.err, "");
}

}  // namespace
}  // namespace vrflow::testing
