// `vrflow validate` and `vrflow run` end to end on files they must not read, write or start:
// description files that are not regular or too large, values too long to echo whole, output
// file parameters outside the working folder, relative executables that are missing.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

CommandResult vrflow(std::vector<std::string> args, double timeoutSeconds = 30) {
  args.insert(args.begin(), binDir() + "/vrflow");
  return runCommand(args, timeoutSeconds);
}

TEST(CliFiles, ValidateRefusesDevZeroAtOnce) {
  const auto result = vrflow({"validate", "/dev/zero"}, 20);
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_EQ(result.err,
            "/dev/zero: error: cannot read file (it is a character device, not a regular file)\n");
}

TEST(CliFiles, ValidateRefusesAFifoWithoutWaitingOnIt) {
  TempDir dir;
  const std::string fifo = dir.file("app.xml");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const auto result = vrflow({"validate", fifo}, 20);
  EXPECT_EQ(result.exitCode, 1) << "128 + 9: killed after 20 s waiting on the FIFO";
  EXPECT_EQ(result.err, fifo + ": error: cannot read file (it is a FIFO, not a regular file)\n");
}

TEST(CliFiles, ValidateRefusesAFolderAndAFileAboveTheCap) {
  TempDir dir;
  const auto folder = vrflow({"validate", dir.path()});
  EXPECT_EQ(folder.exitCode, 1);
  EXPECT_EQ(folder.err,
            dir.path() + ": error: cannot read file (it is a directory, not a regular file)\n");
  const std::string big = dir.write("big.xml", "<application name=\"a\" version=\"1\">");
  std::filesystem::resize_file(big, std::uintmax_t{1} << 30);  // 1 GiB, sparse
  const auto huge = vrflow({"validate", big});
  EXPECT_EQ(huge.exitCode, 1);
  EXPECT_EQ(huge.err, big +
                          ": error: cannot read file (it is 1073741824 bytes, above the limit of "
                          "16777216 bytes (16 MiB))\n");
}

// A value of 100 KB in a file, or an id of 10 MB, is echoed cut with its length, so stderr
// stays small (67 MB and 30 MB before).
TEST(CliFiles, LongValuesAreEchoedCutWithTheirLength) {
  TempDir dir;
  const std::string type(100000, 't');
  const auto typeApp = dir.write("type.xml", R"(<application name="a" version="1">
  <modules><module id="m" package="core" type=")" +
                                                 type + R"("/></modules>
</application>
)");
  const auto longType = vrflow({"validate", typeApp});
  EXPECT_EQ(longType.exitCode, 1);
  EXPECT_LT(longType.err.size(), 4096u) << longType.err.substr(0, 1000);
  EXPECT_NE(longType.err.find("\u2026(100005 bytes)'"), std::string::npos)
      << longType.err.substr(0, 1000);

  const std::string id(10 << 20, 'i');
  const auto idApp = dir.write("id.xml", R"(<application name="a" version="1">
  <modules><module id=")" + id + R"(" package="core" type="recorder"/></modules>
</application>
)");
  const auto longId = vrflow({"validate", idApp});
  EXPECT_EQ(longId.exitCode, 1);
  EXPECT_LT(longId.err.size(), 4096u) << longId.err.substr(0, 1000);
  EXPECT_NE(longId.err.find("\u2026(10485760 bytes)'"), std::string::npos)
      << longId.err.substr(0, 1000);
}

// A 100 KB file whose ids are long: every "unknown node" error listed every known id whole, so
// the output grew with (file size)^2 (9.6 MB here); each listed id is now cut too.
TEST(CliFiles, ListsOfKnownIdsAreBoundedToo) {
  TempDir dir;
  std::string xml = "<application name=\"a\" version=\"1\">\n  <modules>\n";
  for (int k = 0; k < 12; ++k) {
    xml += "    <module id=\"" + std::string(8000, static_cast<char>('a' + k)) +
           "\" package=\"core\" type=\"relay\"/>\n";
  }
  xml += "  </modules>\n  <connections>\n";
  for (int k = 0; k < 50; ++k) {
    xml += "    <connection from=\"x" + std::to_string(k) + ".out\" to=\"y.in\"/>\n";
  }
  xml += "  </connections>\n</application>\n";
  const auto result = vrflow({"validate", dir.write("ids.xml", xml)});
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_NE(result.err.find("\u2026(8000 bytes)"), std::string::npos) << result.err.substr(0, 1000);
  EXPECT_LT(result.err.size(), 256u * 1024) << result.err.substr(0, 1000);
}

std::string recorderApp(const std::string& file) {
  return R"(<application name="rec" version="1">
  <modules>
    <module id="src" package="core" type="source"><param name="count" value="3"/></module>
    <module id="rec" package="core" type="recorder"><param name="file" value=")" +
         file + R"("/></module>
  </modules>
  <connections><connection from="src.out" to="rec.in"/></connections>
</application>
)";
}

// The recorder created any missing folder (`recorder.file=/nonexistent/dir/x.csv` made
// /nonexistent/dir). An output's missing folder outside the working folder is now an error of
// `validate` and `run`, and nothing is created.
TEST(CliFiles, OutputFolderOutsideTheWorkingFolderIsNeverCreated) {
  TempDir dir;
  const std::string outside = dir.file("missing/dir/x.csv");
  const auto app = dir.write("app.xml", recorderApp(outside));
  const std::string expected = "names '" + outside +
                               "', an output that cannot be written: folder '" +
                               dir.file("missing/dir") + "' does not exist";
  const auto validated = vrflow({"validate", app});
  EXPECT_EQ(validated.exitCode, 1);
  EXPECT_NE(validated.err.find(expected), std::string::npos) << validated.err;
  const auto ran = vrflow({"run", app, "-n", "3"});
  EXPECT_NE(ran.exitCode, 0);
  EXPECT_NE(ran.err.find(expected), std::string::npos) << ran.err;
  const auto set = vrflow({"run", dir.write("ok.xml", recorderApp(dir.file("x.csv"))), "--set",
                           "rec.file=" + outside, "-n", "3"});
  EXPECT_NE(set.exitCode, 0);
  EXPECT_NE(set.err.find(expected), std::string::npos) << set.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("missing")));
  EXPECT_TRUE(leftoverProcesses().empty());
}

TEST(CliFiles, OutputFolderInsideTheWorkingFolderIsCreated) {
  TempDir dir;
  const auto app = dir.write("app.xml", recorderApp("out/today/x.csv"));
  const auto ran = runCommand(
      {"/bin/sh", "-c", "cd " + dir.path() + " && " + binDir() + "/vrflow run " + app + " -n 3"},
      30);
  EXPECT_EQ(ran.exitCode, 0) << ran.err;
  EXPECT_TRUE(std::filesystem::is_regular_file(dir.file("out/today/x.csv")));
}

// A relative executable that is missing fails naming the manifest and the path it was resolved
// to (it said "cannot start '../../bin/x': No such file or directory").
TEST(CliFiles, MissingRelativeExecutableNamesTheManifestAndTheResolvedPath) {
  TempDir dir;
  std::filesystem::create_directories(dir.file("share/pkg"));
  const std::string manifest = dir.write("share/pkg/vrflow-package.xml", R"(<package name="pkg">
  <module type="m" executable="../../bin/x"/>
</package>
)");
  const auto app = dir.write("app.xml", R"(<application name="a" version="1">
  <modules><module id="m1" package="pkg" type="m"/></modules>
</application>
)");
  const auto ran = vrflow({"--packages", dir.file("share"), "run", app, "-n", "1"});
  EXPECT_NE(ran.exitCode, 0);
  EXPECT_NE(ran.err.find("module 'm1' (pkg/m): cannot start its executable '" + dir.file("bin/x") +
                         "' (No such file or directory), resolved from " + manifest +
                         ":2 against the manifest's folder"),
            std::string::npos)
      << ran.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

}  // namespace
}  // namespace vrflow::testing
