#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/base/result.hpp"

namespace vrflow::ipc {

/// Looks an environment variable up: its value, or null when it is unset (std::getenv's form).
using EnvironmentLookup = std::function<const char*(const char*)>;

/// What the supervisor tells a module process so that it can join the run: where the host's
/// segment is and which slot of its control table is the module's. It travels as environment
/// variables; encode() (the supervisor's side) and decode() (the module's side) are the only
/// places that spell them (docs/shared-memory.md, "Joining a run").
struct JoinContract {
  /// VRFLOW_SEGMENT_FD: the segment's descriptor, inherited; -1 when not given.
  int segmentFd = -1;
  /// VRFLOW_SEGMENT_PATH: a path that opens the segment (/proc/<pid>/fd/<fd>), for processes
  /// started through mpirun, which closes inherited descriptors; empty when not given.
  std::string segmentPath;
  /// VRFLOW_MODULE_INDEX: the module's slot in the control table; -1 when not given.
  int moduleIndex = -1;
  /// VRFLOW_MODULE_INDICES: the slots of an MPI job's modules, in rank order (each rank joins
  /// as the module of its entry); empty when not given.
  std::vector<int> moduleIndices;
  /// VRFLOW_MODULE_ID: the module's id in the application (informative).
  std::string moduleId;
  /// VRFLOW_HOST: the host the module runs on (informative).
  std::string host;
  /// VRFLOW_MPI_JOB: the name of the MPI job the module belongs to, for messages.
  std::string mpiJob;
  /// VRFLOW_MPI_RANKS: the ranks of a module started as several MPI ranks; 0 when not given.
  int mpiRanks = 0;

  /// The "NAME=value" environment entries of the fields that are given.
  std::vector<std::string> encode() const;
  /// Reads the contract; an error names the variable that is missing or malformed.
  static Result<JoinContract> decode(const EnvironmentLookup& lookup);
  /// decode() of this process's environment.
  static Result<JoinContract> decodeEnvironment();
  /// The slot of this process: moduleIndex, or for an MPI job the entry of moduleIndices
  /// chosen by the process's MPI rank (OMPI_COMM_WORLD_RANK or PMIX_RANK, from `lookup`).
  Result<int> slotIndex(const EnvironmentLookup& lookup) const;
  /// True when `entry` ("NAME=value") sets one of the contract's variables.
  static bool isContractEntry(std::string_view entry);
};

}  // namespace vrflow::ipc
