#include "vrflow/ipc/join_contract.hpp"

#include <array>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <optional>

namespace vrflow::ipc {
namespace {

constexpr const char* kSegmentFd = "VRFLOW_SEGMENT_FD";
constexpr const char* kSegmentPath = "VRFLOW_SEGMENT_PATH";
constexpr const char* kModuleIndex = "VRFLOW_MODULE_INDEX";
constexpr const char* kModuleIndices = "VRFLOW_MODULE_INDICES";
constexpr const char* kModuleId = "VRFLOW_MODULE_ID";
constexpr const char* kHost = "VRFLOW_HOST";
constexpr const char* kMpiJob = "VRFLOW_MPI_JOB";
constexpr const char* kMpiRanks = "VRFLOW_MPI_RANKS";
constexpr std::array kAllNames{kSegmentFd, kModuleIndex, kModuleIndices, kModuleId,
                               kHost,      kSegmentPath, kMpiJob,        kMpiRanks};

constexpr const char* kStartedByHand =
    "this program is a vrflow module: start it through an application "
    "(`vrflow run APP.xml`), not by hand";

// A whole decimal number in [0, INT_MAX]; nullopt for anything else.
std::optional<int> parseCount(std::string_view text) {
  if (text.empty()) return std::nullopt;
  long value = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return std::nullopt;
    value = value * 10 + (c - '0');
    if (value > INT_MAX) return std::nullopt;
  }
  return static_cast<int>(value);
}

Error malformed(const char* name, std::string_view text, const char* expected) {
  return Error{"cannot join the run: malformed " + std::string(name) + " '" + std::string(text) +
               "' (expected " + expected + ")"};
}

// Reads the count `name` when the environment sets it (`text` not null) into `out`.
Status readCount(const char* name, const char* text, const char* expected, int minimum, int& out) {
  if (text == nullptr) return {};
  const auto value = parseCount(text);
  if (!value || *value < minimum) return malformed(name, text, expected);
  out = *value;
  return {};
}

}  // namespace

std::vector<std::string> JoinContract::encode() const {
  std::vector<std::string> entries;
  const auto add = [&](const char* name, const std::string& value) {
    entries.push_back(std::string(name) + "=" + value);
  };
  if (segmentFd >= 0) add(kSegmentFd, std::to_string(segmentFd));
  if (!segmentPath.empty()) add(kSegmentPath, segmentPath);
  if (moduleIndex >= 0) add(kModuleIndex, std::to_string(moduleIndex));
  if (!moduleIndices.empty()) {
    std::string list;
    for (const int index : moduleIndices) list += (list.empty() ? "" : ",") + std::to_string(index);
    add(kModuleIndices, list);
  }
  if (!moduleId.empty()) add(kModuleId, moduleId);
  if (!host.empty()) add(kHost, host);
  if (!mpiJob.empty()) add(kMpiJob, mpiJob);
  if (mpiRanks > 0) add(kMpiRanks, std::to_string(mpiRanks));
  return entries;
}

Result<JoinContract> JoinContract::decode(const EnvironmentLookup& lookup) {
  JoinContract contract;
  const char* fd = lookup(kSegmentFd);
  const char* path = lookup(kSegmentPath);
  if (fd == nullptr && path == nullptr) return makeError(kStartedByHand);
  if (auto status = readCount(kSegmentFd, fd, "a descriptor number", 0, contract.segmentFd);
      !status) {
    return status.error();
  }
  if (path != nullptr) {
    if (*path == '\0') return malformed(kSegmentPath, path, "a path");
    contract.segmentPath = path;
  }
  const char* index = lookup(kModuleIndex);
  const char* indices = lookup(kModuleIndices);
  if (index == nullptr && indices == nullptr) return makeError(kStartedByHand);
  if (auto status = readCount(kModuleIndex, index, "a slot index", 0, contract.moduleIndex);
      !status) {
    return status.error();
  }
  if (indices != nullptr) {
    const std::string_view text(indices);
    std::size_t start = 0;
    for (;;) {
      const std::size_t comma = text.find(',', start);
      const auto value = parseCount(text.substr(start, comma - start));
      if (!value) return malformed(kModuleIndices, text, "slot indices separated by ','");
      contract.moduleIndices.push_back(*value);
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
  }
  if (const char* id = lookup(kModuleId)) contract.moduleId = id;
  if (const char* host = lookup(kHost)) contract.host = host;
  if (const char* job = lookup(kMpiJob)) contract.mpiJob = job;
  if (auto status = readCount(kMpiRanks, lookup(kMpiRanks), "a number of ranks above 0", 1,
                              contract.mpiRanks);
      !status) {
    return status.error();
  }
  return contract;
}

Result<JoinContract> JoinContract::decodeEnvironment() {
  return decode([](const char* name) { return std::getenv(name); });
}

Result<int> JoinContract::slotIndex(const EnvironmentLookup& lookup) const {
  if (moduleIndices.empty()) return moduleIndex;
  std::string list;
  for (const int index : moduleIndices) list += (list.empty() ? "" : ",") + std::to_string(index);
  const std::string job = mpiJob.empty() ? std::string() : " '" + mpiJob + "'";
  const char* rankText = nullptr;
  const char* rankName = nullptr;
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK"}) {
    if ((rankText = lookup(name)) != nullptr) {
      rankName = name;
      break;
    }
  }
  if (rankText == nullptr) {
    return makeError("cannot join the run: this process is a module of MPI job" + job + " (" +
                     kModuleIndices + "=" + list +
                     ") but has no MPI rank (neither OMPI_COMM_WORLD_RANK nor PMIX_RANK is set): "
                     "its ranks are started by the runtime's mpirun");
  }
  const auto rank = parseCount(rankText);
  if (!rank || static_cast<std::size_t>(*rank) >= moduleIndices.size()) {
    return makeError("cannot join the run: MPI rank " + std::string(rankText) + " (" + rankName +
                     ") is not a rank of MPI job" + job + ", which has " +
                     std::to_string(moduleIndices.size()) + " module(s) (" + kModuleIndices + "=" +
                     list + "): start the job with as many ranks as modules");
  }
  return moduleIndices[static_cast<std::size_t>(*rank)];
}

bool JoinContract::isContractEntry(std::string_view entry) {
  const std::string_view name = entry.substr(0, entry.find('='));
  for (const char* known : kAllNames) {
    if (name == known) return true;
  }
  return false;
}

}  // namespace vrflow::ipc
