// Hostfiles in vrflow's and Open MPI's formats, and what the mpirun backend does with them.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "cluster_helpers.hpp"
#include "process_helpers.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/launcher/launch.hpp"

namespace vrflow::testing {
namespace {

std::string threeHostsFile() {
  return sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml";
}

app::Application threeHosts() {
  auto application = app::loadApplicationFile(threeHostsFile());
  EXPECT_TRUE(application) << application.error().message;
  return *application;
}

// readHostfile() of `text` written to a file; `path` gets that file's path.
Result<std::vector<launcher::HostEntry>> read(const TempDir& dir, const std::string& text,
                                              std::string& path) {
  path = dir.write("hosts", text);
  return launcher::readHostfile(path, threeHosts());
}

TEST(Hostfile, VrflowFormatKeepsEveryKeyAndSkipsCommentsAndBlankLines) {
  TempDir dir;
  std::string path;
  const auto entries = read(
      dir, "# the cluster\n\na address=10.0.0.1 env=X=1 # host a\n   \nc node=n7 user=me\n", path);
  ASSERT_TRUE(entries) << entries.error().message;
  ASSERT_EQ(entries->size(), 2u);
  EXPECT_EQ((*entries)[0].host, "a");
  EXPECT_EQ((*entries)[0].address, "10.0.0.1");
  EXPECT_EQ((*entries)[0].environment, std::vector<std::string>{"X=1"});
  EXPECT_EQ((*entries)[0].line, 3);
  EXPECT_EQ((*entries)[1].host, "c");
  EXPECT_EQ((*entries)[1].node, "n7");
  EXPECT_EQ((*entries)[1].user, "me");
  EXPECT_EQ((*entries)[1].line, 5);
}

TEST(Hostfile, OpenMpiFormatPlacesTheHostsOnTheSlotsInFileOrder) {
  TempDir dir;
  std::string path;
  const auto entries = read(dir, "# Open MPI\nnode1 slots=2\n\nnode2 slots=1 max_slots=4\n", path);
  ASSERT_TRUE(entries) << entries.error().message;
  ASSERT_EQ(entries->size(), 3u);
  const std::vector<std::pair<std::string, std::string>> expected{
      {"a", "node1"}, {"b", "node1"}, {"c", "node2"}};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ((*entries)[i].host, expected[i].first);
    EXPECT_EQ((*entries)[i].node, expected[i].second);
  }
  EXPECT_EQ((*entries)[2].line, 4);
}

TEST(Hostfile, MaxSlotsTakeTheHostsThatSlotsDoNotHoldAndNameOnlyLinesHoldOne) {
  TempDir dir;
  std::string path;
  const auto entries = read(dir, "n1 max-slots=3\nn2\n", path);
  ASSERT_TRUE(entries) << entries.error().message;
  ASSERT_EQ(entries->size(), 3u);
  EXPECT_EQ((*entries)[0].node, "n1");
  EXPECT_EQ((*entries)[1].node, "n2");
  EXPECT_EQ((*entries)[2].node, "n1");
}

TEST(Hostfile, TooFewSlotsForTheHostsIsAnErrorNamingTheFile) {
  TempDir dir;
  std::string path;
  const auto entries = read(dir, "n1 slots=1\nn2 slots=1 max_slots=1\n", path);
  ASSERT_FALSE(entries);
  EXPECT_EQ(entries.error().message,
            path + ": error: the Open MPI hostfile has 2 slot(s) for the 3 hosts of " +
                threeHostsFile() + " (raise slots= or max_slots=)");
}

TEST(Hostfile, MixedOrMalformedLinesAreOneErrorNamingFileAndLine) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {"a address=10.0.0.1\n\nn1 slots=2\n",
       ":3: error: 'slots=2' mixes the two hostfile formats: line 1 makes this a vrflow hostfile"},
      {"n1 slots=2\nb user=me\n",
       ":2: error: 'user=me' mixes the two hostfile formats: line 1 makes this an Open MPI "
       "hostfile"},
      {"n1 slots=2 user=me\n", ":1: error: 'user=me' mixes the two hostfile formats"},
      {"n1 slots=0\n", ":1: error: bad slots '0' (a whole number >= 1)"},
      {"n1\nn2 slots=two\n", ":2: error: bad slots 'two'"},
      {"n1 slots=3 max_slots=2\n", ":1: error: max_slots=2 is below slots=3"},
      {"# c\nn1 slots=1 cpus\n", ":2: error: unknown word 'cpus' in an Open MPI hostfile"},
      {"a\nb ssh-port=x\n", ":2: error: bad ssh-port 'x'"},
      {"a\nnode1\n", ":2: error: no host 'node1' in " + threeHostsFile() +
                         " (an Open MPI hostfile, naming machines, needs slots= on a line)"},
  };
  for (const auto& [text, message] : cases) {
    TempDir dir;
    std::string path;
    const auto entries = read(dir, text, path);
    ASSERT_FALSE(entries) << text;
    EXPECT_EQ(entries.error().message.rfind(path + message, 0), 0u)
        << text << "\ngot: " << entries.error().message;
  }
}

TEST(Hostfile, MachinesAreRefusedByTheBackendsThatRunEverythingHereOrOverSsh) {
  useOwnHome();
  TempDir dir;
  const auto hosts = dir.write("hosts", "localhost slots=3\n");
  for (const std::string backend : {"local", "ssh"}) {
    const auto result =
        runVrflow({"launch", threeHostsFile(), "--backend", backend, "--hosts", hosts}, 60);
    EXPECT_EQ(result.exitCode, 2) << backend;
    EXPECT_NE(
        result.err.find(hosts + ":1: error: host 'a' is placed on machine 'localhost' (node=, or "
                                "an Open MPI hostfile): only --backend mpirun and slurm"),
        std::string::npos)
        << result.err;
  }
  const auto mpirunArg = runVrflow({"launch", threeHostsFile(), "--mpirun-arg=--oversubscribe"});
  EXPECT_EQ(mpirunArg.exitCode, 2);
  EXPECT_NE(mpirunArg.err.find("--mpirun-arg is for --backend mpirun (this launch uses local)"),
            std::string::npos)
      << mpirunArg.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

// mpirun refuses root unless told; the tests may run as root in a container.
bool mpirunUsable() {
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  return runCommand({"/bin/sh", "-c", "command -v mpirun"}, 10).exitCode == 0;
}

TEST(HostfileMpirun, AnOpenMpiHostfileAndMpirunArgsGiveTheSameDigestsAsOneHost) {
  useOwnHome();
  if (!mpirunUsable()) GTEST_SKIP() << "mpirun is not installed";
  TempDir dir;
  const auto one = runVrflow({"run", sourceDir() + "/examples/pipeline/pipeline.xml", "-n", "60",
                              "--no-progress", "--report", dir.file("one.json")},
                             120);
  ASSERT_EQ(one.exitCode, 0) << one.err;
  const auto hosts = dir.write("hosts", "# one machine, three slots\nlocalhost slots=3\n");
  // --report-pid FILE: mpirun writes its pid there, which shows the words reached mpirun.
  const auto three =
      runVrflow({"launch", threeHostsFile(), "--backend", "mpirun", "--hosts", hosts,
                 "--mpirun-arg=--report-pid", "--mpirun-arg=" + dir.file("mpirun.pid"), "-n", "60",
                 "--report", dir.file("three.json")},
                120);
  ASSERT_EQ(three.exitCode, 0) << three.err;
  EXPECT_EQ(deterministicPart(dir.file("one.json")), deterministicPart(dir.file("three.json")));
  const std::string pid = readFile(dir.file("mpirun.pid"));
  EXPECT_GT(std::atoi(pid.c_str()), 1) << "mpirun wrote no pid: '" << pid << "'";
  EXPECT_TRUE(leftoverProcesses().empty());
}

TEST(HostfileMpirun, TheHostfileAddressesAndEnvironmentReachTheDaemonsUnderMpirun) {
  useOwnHome();
  if (!mpirunUsable()) GTEST_SKIP() << "mpirun is not installed";
  TempDir dir;
  // A copy of the application at a path of this test, to find its daemons among the machine's.
  const std::string appFile = dir.write("pipeline_3hosts.xml", readFile(threeHostsFile()));
  const auto hosts = dir.write(
      "hosts", "a address=127.0.0.5\nb env=VRFLOW_TEST_MARK=bee env=SECOND=2\n# c: as the file\n");
  CommandResult result;
  // An endless launch, interrupted after 8 s (Ctrl-C): the daemons are looked at meanwhile.
  std::thread launch([&] {
    result = runVrflow({"launch", appFile, "--backend", "mpirun", "--hosts", hosts, "-n", "0"}, 60,
                       8, SIGINT);
  });
  const DaemonSeen a = findDaemon(appFile, "a");
  const DaemonSeen b = findDaemon(appFile, "b");
  const std::string &envA = a.environment, &argsA = a.commandLine;
  const std::string &envB = b.environment, &argsB = b.commandLine;
  launch.join();
  EXPECT_EQ(result.exitCode, 130) << result.err;
  EXPECT_NE(argsA.find("--bind 127.0.0.5 "), std::string::npos) << argsA;
  EXPECT_NE(argsB.find("--bind 127.0.0.2 "), std::string::npos) << argsB;
  EXPECT_NE(envB.find("\nVRFLOW_TEST_MARK=bee\n"), std::string::npos) << envB;
  EXPECT_NE(envB.find("\nSECOND=2\n"), std::string::npos) << envB;
  EXPECT_EQ(envA.find("VRFLOW_TEST_MARK"), std::string::npos) << envA;
  EXPECT_FALSE(envA.empty());
  EXPECT_TRUE(leftoverProcesses().empty());
}

}  // namespace
}  // namespace vrflow::testing
