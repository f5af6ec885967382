// MPI jobs made of several modules (ModuleType::mpiJobParam): one host per job, and no module
// of a job that also starts ranks of its own (mpi-ranks above 1).
#include <algorithm>
#include <optional>
#include <utility>

#include "text_util.hpp"
#include "validation.hpp"
#include "vrflow/app/mpi_job.hpp"

namespace vrflow::app::detail {
namespace {

// "b0, b2 on host 'a'; b1 on host 'b'", hosts in the order of their first module.
std::string modulesByHost(const Validation& v, const MpiJob& job) {
  std::vector<std::pair<std::string, std::vector<std::string>>> hosts;
  for (const std::size_t m : job.modules) {
    const Module& module = v.app.modules[m];
    const std::string host = effectiveHost(v.app, module.host);
    auto it = std::find_if(hosts.begin(), hosts.end(),
                           [&](const auto& entry) { return entry.first == host; });
    if (it == hosts.end()) it = hosts.insert(hosts.end(), {host, {}});
    it->second.push_back(module.id);
  }
  std::string text;
  for (const auto& [host, ids] : hosts) {
    text += (text.empty() ? "" : "; ") + joinNames(ids) + " on host '" + host + "'";
  }
  return text;
}

void checkOneHost(Validation& v, const MpiJob& job) {
  const std::string first = effectiveHost(v.app, v.app.modules[job.modules.front()].host);
  for (const std::size_t m : job.modules) {
    const Module& module = v.app.modules[m];
    if (effectiveHost(v.app, module.host) == first) continue;
    v.error(module.loc.attribute("host"),
            "module '" + module.id + "' is on host '" + effectiveHost(v.app, module.host) +
                "' but MPI job '" + job.name + "' (" + job.package + "/" + job.type +
                ") began on host '" + first + "' (" + modulesByHost(v, job) +
                "): the modules of one MPI job must be on one host (MPI jobs across hosts are "
                "not supported yet)");
    return;  // one error per job
  }
}

void checkNoOwnRanks(Validation& v, const MpiJob& job) {
  const ModuleType* type = v.catalog.findModule(job.package, job.type);
  if (type == nullptr || type->mpiRanksParam.empty()) return;
  for (const std::size_t m : job.modules) {
    const Module& module = v.app.modules[m];
    const std::optional<long long> ranks =
        parseInteger(effectiveParamValue(module, *type, type->mpiRanksParam));
    if (!ranks || *ranks <= 1) continue;  // a bad value is reported with the parameters
    const Param* set = findParam(module.params, type->mpiRanksParam);
    v.error(set != nullptr ? set->loc.attribute("value") : module.loc,
            "module '" + module.id + "' runs as one rank of MPI job '" + job.name + "' (its '" +
                type->mpiJobParam + "' parameter), so its '" + type->mpiRanksParam +
                "' parameter must be 1, got " + std::to_string(*ranks) +
                " (a module of an MPI job cannot start ranks of its own)");
  }
}

}  // namespace

void checkMpiJobs(Validation& v) {
  for (const MpiJob& job : mpiJobs(v.app, v.catalog)) {
    checkOneHost(v, job);
    checkNoOwnRanks(v, job);
  }
}

}  // namespace vrflow::app::detail
