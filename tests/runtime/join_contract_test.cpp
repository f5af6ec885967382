#include "vrflow/ipc/join_contract.hpp"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

namespace vrflow::ipc {
namespace {

// An environment made of "NAME=value" entries, looked up as std::getenv would.
class FakeEnvironment {
 public:
  explicit FakeEnvironment(const std::vector<std::string>& entries) {
    for (const auto& entry : entries) {
      const auto eq = entry.find('=');
      values_[entry.substr(0, eq)] = entry.substr(eq + 1);
    }
  }
  EnvironmentLookup lookup() const {
    return [this](const char* name) -> const char* {
      const auto found = values_.find(name);
      return found == values_.end() ? nullptr : found->second.c_str();
    };
  }

 private:
  std::map<std::string, std::string> values_;
};

Result<JoinContract> decodeOf(const std::vector<std::string>& entries) {
  const FakeEnvironment environment(entries);
  return JoinContract::decode(environment.lookup());
}

// The error text of decoding `entries`, or "" when it decodes.
std::string errorOf(const std::vector<std::string>& entries) {
  const auto decoded = decodeOf(entries);
  return decoded ? std::string() : decoded.error().message;
}

TEST(JoinContract, WhatTheSupervisorEncodesTheModuleDecodes) {
  JoinContract sent;
  sent.segmentFd = 7;
  sent.moduleIndex = 3;
  sent.moduleId = "viewer";
  sent.host = "wall-1";
  sent.mpiJob = "water";
  sent.mpiRanks = 4;
  const auto got = decodeOf(sent.encode());
  ASSERT_TRUE(got.ok()) << got.error().message;
  EXPECT_EQ(got->segmentFd, 7);
  EXPECT_TRUE(got->segmentPath.empty());
  EXPECT_EQ(got->moduleIndex, 3);
  EXPECT_TRUE(got->moduleIndices.empty());
  EXPECT_EQ(got->moduleId, "viewer");
  EXPECT_EQ(got->host, "wall-1");
  EXPECT_EQ(got->mpiJob, "water");
  EXPECT_EQ(got->mpiRanks, 4);
  const auto slot = got->slotIndex(FakeEnvironment({}).lookup());
  ASSERT_TRUE(slot.ok());
  EXPECT_EQ(*slot, 3);
}

TEST(JoinContract, AnMpiJobsRanksEachJoinAsTheModuleOfTheirEntry) {
  JoinContract sent;
  sent.segmentPath = "/proc/42/fd/5";
  sent.moduleIndices = {4, 7, 9};
  sent.mpiJob = "water";
  const auto got = decodeOf(sent.encode());
  ASSERT_TRUE(got.ok()) << got.error().message;
  EXPECT_EQ(got->segmentFd, -1);
  EXPECT_EQ(got->segmentPath, "/proc/42/fd/5");
  EXPECT_EQ(got->moduleIndices, (std::vector<int>{4, 7, 9}));
  EXPECT_EQ(*got->slotIndex(FakeEnvironment({"OMPI_COMM_WORLD_RANK=1"}).lookup()), 7);
  EXPECT_EQ(*got->slotIndex(FakeEnvironment({"PMIX_RANK=2"}).lookup()), 9);
}

TEST(JoinContract, OnlyTheFieldsGivenAreEncoded) {
  JoinContract sent;
  sent.segmentFd = 0;
  sent.moduleIndex = 0;
  EXPECT_EQ(sent.encode(),
            (std::vector<std::string>{"VRFLOW_SEGMENT_FD=0", "VRFLOW_MODULE_INDEX=0"}));
}

TEST(JoinContract, AProgramStartedByHandIsToldHowToStartIt) {
  EXPECT_NE(errorOf({}).find("start it through an application"), std::string::npos);
  EXPECT_NE(errorOf({"VRFLOW_SEGMENT_FD=3"}).find("not by hand"), std::string::npos);
}

TEST(JoinContract, MalformedNumbersAreErrorsNamingTheVariable) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
      {{"VRFLOW_SEGMENT_FD=x", "VRFLOW_MODULE_INDEX=1"}, "malformed VRFLOW_SEGMENT_FD 'x'"},
      {{"VRFLOW_SEGMENT_FD=-3", "VRFLOW_MODULE_INDEX=1"}, "malformed VRFLOW_SEGMENT_FD '-3'"},
      {{"VRFLOW_SEGMENT_FD=", "VRFLOW_MODULE_INDEX=1"}, "malformed VRFLOW_SEGMENT_FD ''"},
      {{"VRFLOW_SEGMENT_FD=3", "VRFLOW_MODULE_INDEX=1x"}, "malformed VRFLOW_MODULE_INDEX '1x'"},
      {{"VRFLOW_SEGMENT_FD=3", "VRFLOW_MODULE_INDEX=99999999999"},
       "malformed VRFLOW_MODULE_INDEX '99999999999'"},
      {{"VRFLOW_SEGMENT_PATH=/p", "VRFLOW_MODULE_INDICES=4,,7"},
       "malformed VRFLOW_MODULE_INDICES '4,,7' (expected slot indices separated by ',')"},
      {{"VRFLOW_SEGMENT_PATH=/p", "VRFLOW_MODULE_INDICES=4,"}, "malformed VRFLOW_MODULE_INDICES"},
      {{"VRFLOW_SEGMENT_PATH=/p", "VRFLOW_MODULE_INDICES="}, "malformed VRFLOW_MODULE_INDICES"},
      {{"VRFLOW_SEGMENT_PATH=", "VRFLOW_MODULE_INDEX=1"}, "malformed VRFLOW_SEGMENT_PATH"},
      {{"VRFLOW_SEGMENT_FD=3", "VRFLOW_MODULE_INDEX=1", "VRFLOW_MPI_RANKS=0"},
       "malformed VRFLOW_MPI_RANKS '0'"},
      {{"VRFLOW_SEGMENT_FD=3", "VRFLOW_MODULE_INDEX=1", "VRFLOW_MPI_RANKS=two"},
       "malformed VRFLOW_MPI_RANKS 'two'"}};
  for (const auto& [entries, expected] : cases) {
    const std::string error = errorOf(entries);
    EXPECT_NE(error.find("cannot join the run: " + expected), std::string::npos)
        << entries.back() << ": " << error;
  }
}

TEST(JoinContract, ARankOutsideTheJobOrWithoutANumberCannotJoin) {
  const auto got =
      decodeOf({"VRFLOW_SEGMENT_PATH=/p", "VRFLOW_MODULE_INDICES=4,7", "VRFLOW_MPI_JOB=water"});
  ASSERT_TRUE(got.ok()) << got.error().message;
  const auto none = got->slotIndex(FakeEnvironment({}).lookup());
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().message.find("is a module of MPI job 'water' (VRFLOW_MODULE_INDICES=4,7) "
                                      "but has no MPI rank"),
            std::string::npos)
      << none.error().message;
  for (const char* rank : {"2", "-1", "x", ""}) {
    const auto slot =
        got->slotIndex(FakeEnvironment({std::string("OMPI_COMM_WORLD_RANK=") + rank}).lookup());
    ASSERT_FALSE(slot.ok()) << rank;
    EXPECT_NE(slot.error().message.find("MPI rank " + std::string(rank) +
                                        " (OMPI_COMM_WORLD_RANK) is not a rank of MPI job 'water'"),
              std::string::npos)
        << slot.error().message;
  }
}

TEST(JoinContract, InheritedContractEntriesAreRecognisedAndNothingElse) {
  for (const char* entry :
       {"VRFLOW_SEGMENT_FD=3", "VRFLOW_SEGMENT_PATH=/p", "VRFLOW_MODULE_INDEX=1",
        "VRFLOW_MODULE_INDICES=1,2", "VRFLOW_MODULE_ID=a", "VRFLOW_HOST=h", "VRFLOW_MPI_JOB=j",
        "VRFLOW_MPI_RANKS=2"}) {
    EXPECT_TRUE(JoinContract::isContractEntry(entry)) << entry;
  }
  for (const char* entry : {"VRFLOW_MPIRUN=none", "VRFLOW_SEGMENT_FDX=3", "PATH=/bin",
                            "VRFLOW_HOSTNAME=x", "VRFLOW_MODULE_INDEXES=1"}) {
    EXPECT_FALSE(JoinContract::isContractEntry(entry)) << entry;
  }
}

}  // namespace
}  // namespace vrflow::ipc
