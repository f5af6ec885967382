// Object ids do not depend on placement (docs/message-layout.md, "Ids"): a module's ids are the
// same whichever slot it has on its host, whichever host runs it, and whether one daemon or
// several serve the application.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "process_helpers.hpp"
#include "vrflow/message/ids.hpp"

namespace vrflow::testing {
namespace {

// A core/points module `id` on `host`, recorded by `rec-<id>` into `csv`.
std::string pointsAndRecorder(const std::string& id, const std::string& host,
                              const std::string& csv) {
  return "    <module id=\"" + id + "\" package=\"core\" type=\"points\" host=\"" + host +
         "\">\n      <param name=\"count\" value=\"3\"/>\n    </module>\n"
         "    <module id=\"rec-" +
         id + "\" package=\"core\" type=\"recorder\" host=\"" + host +
         "\">\n      <param name=\"file\" value=\"" + csv + "\"/>\n    </module>\n";
}

std::string application(const std::string& hosts, const std::string& modules,
                        const std::vector<std::string>& recorded) {
  std::string connections;
  for (const auto& id : recorded) {
    connections += "    <connection from=\"" + id + ".objects\" to=\"rec-" + id + ".in\"/>\n";
  }
  return "<application name=\"ids\" version=\"1\">\n  <hosts>\n" + hosts + "  </hosts>\n" +
         "  <modules>\n" + modules + "  </modules>\n  <connections>\n" + connections +
         "  </connections>\n</application>\n";
}

// The object ids a recorder wrote, in order.
std::vector<std::uint64_t> recordedIds(const std::string& csv) {
  std::vector<std::uint64_t> ids;
  for (const auto& cells : readCsvRows(csv)) {
    if (cells.size() > 5 && cells[4] == "object") ids.push_back(std::stoull(cells[5]));
  }
  return ids;
}

// A hostfile binding hosts a and b to 127.0.51.A and 127.0.51.B (this test's own addresses).
std::string loopbackHostfile(const TempDir& dir, const std::string& a, const std::string& b) {
  return dir.write("hosts-" + a + b,
                   "a address=127.0.51." + a + "\nb address=127.0.51." + b + "\n");
}

class IdsAcrossPlacements : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty());
    EXPECT_TRUE(vrflowShmEntries().empty());
  }
  TempDir dir;
};

TEST_F(IdsAcrossPlacements, AModuleMovedToAnotherSlotOrHostMakesTheSameIds) {
  // First alone on host 127.0.0.1 (slot 0); then third on a host of another address, after
  // another points module; then on the second of two hosts under `vrflow launch`.
  const std::string alone = dir.write(
      "alone.xml", application("    <host id=\"local\" address=\"127.0.0.1\"/>\n",
                               pointsAndRecorder("pts", "local", dir.file("alone.csv")), {"pts"}));
  const std::string moved = dir.write(
      "moved.xml", application("    <host id=\"node\" address=\"127.0.51.9\"/>\n",
                               pointsAndRecorder("other", "node", dir.file("other.csv")) +
                                   pointsAndRecorder("pts", "node", dir.file("moved.csv")),
                               {"other", "pts"}));
  const std::string twoHosts =
      dir.write("two.xml", application("    <host id=\"a\" address=\"127.0.51.1\"/>\n"
                                       "    <host id=\"b\" address=\"127.0.51.2\"/>\n",
                                       pointsAndRecorder("other", "a", dir.file("other2.csv")) +
                                           pointsAndRecorder("pts", "b", dir.file("two.csv")),
                                       {"other", "pts"}));
  for (const auto& file : {alone, moved}) {
    const auto run = runVrflow({"run", file, "-n", "2", "--no-progress"}, 60);
    ASSERT_EQ(run.exitCode, 0) << run.err;
  }
  const auto launched = runVrflow({"launch", twoHosts, "--hosts", loopbackHostfile(dir, "1", "2"),
                                   "--backend", "local", "-n", "2", "--no-progress"},
                                  120);
  ASSERT_EQ(launched.exitCode, 0) << launched.err;

  const std::uint32_t prefix = msg::fnv1a32("pts");
  const std::vector<std::uint64_t> expected{msg::makeId(prefix, 1), msg::makeId(prefix, 2),
                                            msg::makeId(prefix, 3), msg::makeId(prefix, 1),
                                            msg::makeId(prefix, 2), msg::makeId(prefix, 3)};
  EXPECT_EQ(recordedIds(dir.file("alone.csv")), expected);
  EXPECT_EQ(recordedIds(dir.file("moved.csv")), expected);
  EXPECT_EQ(recordedIds(dir.file("two.csv")), expected);
  // The other module's ids are its own.
  const auto other = recordedIds(dir.file("other.csv"));
  ASSERT_EQ(other.size(), 6u);
  EXPECT_EQ(msg::prefixOf(other[0]), msg::fnv1a32("other"));
  EXPECT_EQ(recordedIds(dir.file("other2.csv")), other);
}

// "pyqjpcv" and "xgoik67" have the same FNV-1a 32: the smaller id keeps it, the other takes the
// next value, whichever comes first in the file and whichever host runs it.
TEST_F(IdsAcrossPlacements, ModulesWhoseHashesCollideGetDistinctDeterministicPrefixes) {
  ASSERT_EQ(msg::fnv1a32("pyqjpcv"), msg::fnv1a32("xgoik67"));
  const std::string oneHost = dir.write(
      "one.xml", application("    <host id=\"local\" address=\"127.0.0.1\"/>\n",
                             pointsAndRecorder("xgoik67", "local", dir.file("x1.csv")) +
                                 pointsAndRecorder("pyqjpcv", "local", dir.file("p1.csv")),
                             {"xgoik67", "pyqjpcv"}));
  const std::string twoHosts =
      dir.write("two.xml", application("    <host id=\"a\" address=\"127.0.51.3\"/>\n"
                                       "    <host id=\"b\" address=\"127.0.51.4\"/>\n",
                                       pointsAndRecorder("pyqjpcv", "a", dir.file("p2.csv")) +
                                           pointsAndRecorder("xgoik67", "b", dir.file("x2.csv")),
                                       {"pyqjpcv", "xgoik67"}));
  const auto run = runVrflow({"run", oneHost, "-n", "1", "--no-progress"}, 60);
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const auto launched = runVrflow({"launch", twoHosts, "--hosts", loopbackHostfile(dir, "3", "4"),
                                   "--backend", "local", "-n", "1", "--no-progress"},
                                  120);
  ASSERT_EQ(launched.exitCode, 0) << launched.err;
  const std::uint32_t hash = msg::fnv1a32("pyqjpcv");
  for (const char* csv : {"p1.csv", "p2.csv"}) {
    const auto ids = recordedIds(dir.file(csv));
    ASSERT_EQ(ids.size(), 3u) << csv;
    for (const auto id : ids) EXPECT_EQ(msg::prefixOf(id), hash) << csv;
  }
  for (const char* csv : {"x1.csv", "x2.csv"}) {
    const auto ids = recordedIds(dir.file(csv));
    ASSERT_EQ(ids.size(), 3u) << csv;
    for (const auto id : ids) EXPECT_EQ(msg::prefixOf(id), hash + 1) << csv;
  }
}

}  // namespace
}  // namespace vrflow::testing
