// `vrflow record`, `vrflow replay` and `vrflow inspect` end to end on examples/pipeline: a
// recorded producer replayed in place of itself gives the live run's digests; bad input is one
// clear error and leaves nothing behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "process_helpers.hpp"
#include "vrflow/record/format.hpp"

namespace {

using namespace vrflow::testing;

std::string pipeline() {
  return sourceDir() + "/examples/pipeline/pipeline.xml";
}

// `vrflow ARGS` run in `folder` (the run's working folder: the pipeline writes its CSV there).
CommandResult vrflowIn(const std::string& folder, const std::string& args) {
  std::filesystem::create_directories(folder);
  return runCommand({"/bin/sh", "-c", "cd " + folder + " && " + binDir() + "/vrflow " + args}, 120);
}

// MODULE.PORT -> "messages:last_digest" of every output in a report; the replay's out0 of
// `replayed` is named by the port it stands for.
std::map<std::string, std::string> digests(const std::string& report,
                                           const std::string& replayed = "",
                                           const std::string& port = "") {
  std::map<std::string, std::string> all;
  const auto json = nlohmann::json::parse(readFile(report));
  for (const auto& o : json["outputs"]) {
    std::string name = o["module"].get<std::string>() + "." + o["port"].get<std::string>();
    if (name == replayed + ".out0") name = replayed + "." + port;
    all[name] = o["messages"].dump() + ":" + o["last_digest"].dump();
  }
  return all;
}

TEST(RecordCommands, ReplayingARecordedProducerGivesTheLiveRunsDigests) {
  TempDir dir;
  const auto live = vrflowIn(dir.file("live"), "run " + pipeline() + " -n 50 --report live.json");
  ASSERT_EQ(live.exitCode, 0) << live.err;
  // Two outputs: through the multiplex filter, each message filed under its sender.
  const auto recorded =
      vrflowIn(dir.file("rec"), "record " + pipeline() +
                                    " --connections chain.objects,springs.forces -o chain.vrrec "
                                    "-n 50 --report rec.json --no-progress");
  ASSERT_EQ(recorded.exitCode, 0) << recorded.err;
  const std::string recording = dir.file("rec/chain.vrrec");
  ASSERT_TRUE(std::filesystem::exists(recording));
  const auto replayed = vrflowIn(dir.file("replay"), "replay " + recording + " " + pipeline() +
                                                         " --replace chain --pace fast -n 50 "
                                                         "--report replay.json --no-progress");
  ASSERT_EQ(replayed.exitCode, 0) << replayed.err;

  const auto liveDigests = digests(dir.file("live/live.json"));
  EXPECT_EQ(digests(dir.file("rec/rec.json")), liveDigests);
  EXPECT_EQ(digests(dir.file("replay/replay.json"), "chain", "objects"), liveDigests);
  EXPECT_TRUE(liveDigests.contains("chain.objects"));
  EXPECT_TRUE(liveDigests.contains("springs.forces"));
  // What the network's own recorder wrote downstream of the replay is the live run's, line by line.
  const std::string trajectory = "out/demo/trajectory.csv";
  EXPECT_EQ(readFile(dir.file("replay/" + trajectory)), readFile(dir.file("live/" + trajectory)));
  EXPECT_EQ(readLines(dir.file("live/" + trajectory)).size(), 1u + 50u * 8u);

  // inspect: both connections, 50 messages each.
  const auto text = vrflowIn(dir.path(), "inspect " + recording);
  ASSERT_EQ(text.exitCode, 0) << text.err;
  EXPECT_NE(text.out.find("chain.objects | type objects | 50 messages"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("springs.forces | type events | 50 messages"), std::string::npos)
      << text.out;
  const auto json = vrflowIn(dir.path(), "inspect --json " + recording);
  ASSERT_EQ(json.exitCode, 0) << json.err;
  const auto info = nlohmann::json::parse(json.out);
  EXPECT_EQ(info["version"], vrflow::record::kFormatVersion);
  EXPECT_EQ(info["closed"], true);
  EXPECT_EQ(info["messages"], 100);
  EXPECT_EQ(info["connections"][0]["last_iteration"], 49);
  EXPECT_GT(info["compression_ratio"].get<double>(), 1.0);
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
}

TEST(RecordCommands, ReplayAtTheRecordedPaceGivesTheSameDigestsToo) {
  TempDir dir;
  const auto recorded =
      vrflowIn(dir.file("rec"), "record " + pipeline() +
                                    " --connections chain.objects -o c.vrrec -n 20 "
                                    "--report rec.json --no-progress");
  ASSERT_EQ(recorded.exitCode, 0) << recorded.err;
  const auto replayed =
      vrflowIn(dir.file("replay"), "replay " + dir.file("rec/c.vrrec") + " " + pipeline() +
                                       " --replace chain -n 20 --report r.json "
                                       "--no-progress");
  ASSERT_EQ(replayed.exitCode, 0) << replayed.err;
  EXPECT_EQ(digests(dir.file("replay/r.json"), "chain", "objects"),
            digests(dir.file("rec/rec.json")));
  EXPECT_TRUE(leftoverProcesses().empty());
}

// pace step: one recorded iteration per message on beginIt, here the downstream recorder's
// endIt (a cycle started by one initial message), in the live run and in the replay alike.
TEST(RecordCommands, ReplaySteppedByBeginItGivesTheSameDigests) {
  TempDir dir;
  std::string xml = readFile(pipeline());
  const auto insert = [&xml](const std::string& after, const std::string& text) {
    const auto at = xml.find(after);
    ASSERT_NE(at, std::string::npos) << after;
    xml.insert(at + after.size(), text);
  };
  insert(R"(<input port="events" initial-messages="1"/>)",
         R"(<input port="beginIt" initial-messages="1"/>)");
  insert(R"(<connection from="relay.out" to="recorder.in"/>)",
         R"(<connection from="recorder.endIt" to="chain.beginIt"/>)");
  const std::string app = dir.write("stepped.xml", xml);
  const auto recorded = vrflowIn(
      dir.file("rec"), "record " + app +
                           " --connections chain.objects -o s.vrrec -n 30 --report rec.json "
                           "--no-progress");
  ASSERT_EQ(recorded.exitCode, 0) << recorded.err;
  const auto replayed =
      vrflowIn(dir.file("replay"), "replay " + dir.file("rec/s.vrrec") + " " + app +
                                       " --replace chain --pace step -n 30 --report r.json "
                                       "--no-progress");
  ASSERT_EQ(replayed.exitCode, 0) << replayed.err;
  const auto live = digests(dir.file("rec/rec.json"));
  EXPECT_TRUE(live.contains("recorder.endIt"));
  EXPECT_EQ(digests(dir.file("replay/r.json"), "chain", "objects"), live);
  EXPECT_TRUE(leftoverProcesses().empty());
}

// One line on stderr, exit status 2.
void expectOneError(const CommandResult& result, const std::string& expected) {
  EXPECT_EQ(result.exitCode, 2) << result.err;
  EXPECT_NE(result.err.find(expected), std::string::npos) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
}

TEST(RecordCommands, BadInputIsOneClearErrorAndLeavesNothingBehind) {
  TempDir dir;
  const std::string missing = dir.file("missing.vrrec");
  expectOneError(vrflowIn(dir.path(), "inspect " + missing),
                 "vrflow inspect: cannot read '" + missing + "': No such file or directory");
  expectOneError(vrflowIn(dir.path(), "replay " + missing + " " + pipeline() + " --replace chain"),
                 "vrflow replay: cannot read '" + missing + "'");
  expectOneError(vrflowIn(dir.path(), "record " + pipeline() + " --connections chain.nope -n 5"),
                 "vrflow record: --connections: 'chain.nope': module 'chain' (core/points) has no "
                 "output 'nope' (its outputs: objects)");
  expectOneError(vrflowIn(dir.path(), "record " + pipeline() + " --connections ghost.objects -n 5"),
                 "has no module 'ghost'");
  expectOneError(vrflowIn(dir.path(), "record " + pipeline() +
                                          " --connections chain.objects -o nowhere/c.vrrec -n 5"),
                 "vrflow record: cannot write the recording to 'nowhere/c.vrrec': folder '" +
                     dir.file("nowhere") + "' does not exist");
  expectOneError(vrflowIn(dir.path(), "record " + pipeline() + " --connections chain -n 5"),
                 "'chain' is not MODULE.PORT");

  const auto recorded = vrflowIn(dir.path(), "record " + pipeline() +
                                                 " --connections chain.objects -o c.vrrec -n 5 "
                                                 "--no-progress");
  ASSERT_EQ(recorded.exitCode, 0) << recorded.err;
  const std::string recording = dir.file("c.vrrec");
  expectOneError(
      vrflowIn(dir.path(), "replay " + recording + " " + pipeline() + " --replace springs"),
      "'" + recording + "' holds no output of module 'springs' (it holds: chain.objects)");
  expectOneError(
      vrflowIn(dir.path(), "replay " + recording + " " + pipeline() + " --replace ghost"),
      "has no module 'ghost'");

  // Truncated, corrupted, another version: one error each, naming the byte.
  const std::string bytes = readFile(recording);
  const std::string truncated = dir.write("truncated.vrrec", bytes.substr(0, bytes.size() / 2));
  expectOneError(
      vrflowIn(dir.path(), "replay " + truncated + " " + pipeline() + " --replace chain"),
      "(truncated)");
  expectOneError(vrflowIn(dir.path(), "inspect " + truncated),
                 "vrflow inspect: " + truncated + ": byte ");
  std::string flipped = bytes;
  flipped[vrflow::record::kFileHeaderBytes + 200] ^= 0x5a;
  const std::string corrupted = dir.write("corrupted.vrrec", flipped);
  expectOneError(
      vrflowIn(dir.path(), "replay " + corrupted + " " + pipeline() + " --replace chain"),
      "vrflow replay: " + corrupted + ": byte ");
  std::string older = bytes;
  older[8] = 0;  // version 0: a format before this one
  const std::string old = dir.write("old.vrrec", older);
  expectOneError(vrflowIn(dir.path(), "replay " + old + " " + pipeline() + " --replace chain"),
                 "recording format version 0; this vrflow reads version 1 only");

  // A replay stepped by nothing: the module says why, the run fails.
  const auto stepped = vrflowIn(dir.path(), "replay " + recording + " " + pipeline() +
                                                " --replace chain --pace step -n 5 --no-progress");
  EXPECT_NE(stepped.exitCode, 0);
  EXPECT_NE(stepped.err.find("pace 'step' sends one recorded iteration per message on its "
                             "beginIt input, and nothing is connected to it"),
            std::string::npos)
      << stepped.err;
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
}

}  // namespace
