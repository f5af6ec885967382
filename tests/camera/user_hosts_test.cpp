// One host against three: the camera user's application run with `vrflow run` on one host and
// with `vrflow launch` on three loopback hosts (127.0.51.1-3, the local backend) gives the same
// digest for every output, and the same final states. Object ids name the module that made them,
// not its host or slot (docs/message-layout.md, "Ids"); before that was so, moving the user's
// modules to another host changed the ids of its objects and the digests.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

// Copies `example`'s folder into `dir` and writes beside it `name`: `file` with its one host
// replaced by hosts a, b and c and each module on the host `hosts` gives it.
std::string threeHostVariant(const TempDir& dir, const std::string& example,
                             const std::string& file, const std::string& name,
                             const std::map<std::string, std::string>& hosts) {
  std::filesystem::copy(
      example, dir.path(),
      std::filesystem::copy_options::recursive | std::filesystem::copy_options::overwrite_existing);
  std::string text = readFile(example + "/" + file);
  text = std::regex_replace(text, std::regex(R"(<host id="local"[^>]*/>)"),
                            R"(<host id="a" address="127.0.51.1"/>
    <host id="b" address="127.0.51.2"/>
    <host id="c" address="127.0.51.3"/>)");
  for (const auto& [module, host] : hosts) {
    text = std::regex_replace(
        text, std::regex("(<module id=\"" + module + "\"[^>]*host=\")local\""), "$1" + host + "\"");
  }
  EXPECT_EQ(text.find("host=\"local\""), std::string::npos) << "a module was left on 'local'";
  return dir.write(name, text);
}

// The outputs' digests of a report, by "module.port".
std::map<std::string, nlohmann::json> outputs(const std::string& report) {
  std::map<std::string, nlohmann::json> byPort;
  const auto json = nlohmann::json::parse(readFile(report));
  for (const auto& output : json["outputs"]) {
    byPort[output["module"].get<std::string>() + "." + output["port"].get<std::string>()] = output;
  }
  return byPort;
}

TEST(CameraUserHosts, OneHostAndThreeHostsGiveTheSameDigestsForEveryOutput) {
  TempDir dir;
  const std::string example = sourceDir() + "/examples/camera_user_small";
  // The user on host a, the rigid bodies on b, the net and the viewer on c.
  const std::string three = threeHostVariant(dir, example, "camera_user_small.xml", "three.xml",
                                             {{"truth", "a"},
                                              {"user", "a"},
                                              {"bodies", "b"},
                                              {"contacts", "b"},
                                              {"field", "b"},
                                              {"net", "c"},
                                              {"net-contacts", "c"},
                                              {"view", "c"}});
  const std::string hostfile =
      dir.write("hosts", "a address=127.0.51.1\nb address=127.0.51.2\nc address=127.0.51.3\n");
  std::filesystem::create_directories(dir.file("one"));
  std::filesystem::create_directories(dir.file("three"));
  const std::string iterations = "120";
  const auto one = runCommand({"/bin/sh", "-c",
                               "cd '" + dir.file("one") + "' && exec '" + binDir() +
                                   "/vrflow' run '" + dir.file("camera_user_small.xml") + "' -n " +
                                   iterations + " --no-progress --report report.json"},
                              300);
  ASSERT_EQ(one.exitCode, 0) << one.err;
  const auto launched =
      runCommand({"/bin/sh", "-c",
                  "cd '" + dir.file("three") + "' && exec '" + binDir() + "/vrflow' launch '" +
                      three + "' --hosts '" + hostfile + "' --backend local -n " + iterations +
                      " --no-progress --report report.json"},
                 300);
  ASSERT_EQ(launched.exitCode, 0) << launched.err;

  const auto a = outputs(dir.file("one/report.json"));
  const auto b = outputs(dir.file("three/report.json"));
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GE(a.size(), 7u);
  for (const auto& [port, output] : a) {
    ASSERT_TRUE(b.contains(port)) << port;
    EXPECT_EQ(output["last_digest"], b.at(port)["last_digest"]) << port;
    EXPECT_EQ(output["messages"], b.at(port)["messages"]) << port;
  }
  EXPECT_EQ(readFile(dir.file("one/bodies-final.json")),
            readFile(dir.file("three/bodies-final.json")));
  EXPECT_EQ(readFile(dir.file("one/net-final.txt")), readFile(dir.file("three/net-final.txt")));
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
}

}  // namespace
}  // namespace vrflow::testing
