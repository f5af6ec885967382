#include "vrflow/app/mpi_job.hpp"

#include <map>
#include <tuple>

namespace vrflow::app {

std::string MpiJob::moduleIds(const Application& application) const {
  std::string text;
  for (const std::size_t m : modules) {
    text += (text.empty() ? "" : ", ") + application.modules[m].id;
  }
  return text;
}

std::string effectiveParamValue(const Module& module, const ModuleType& type,
                                std::string_view name) {
  if (const Param* own = findParam(module.params, name)) return own->value;
  if (const ParamSpec* spec = type.findParam(name)) return spec->defaultValue;
  return {};
}

std::vector<MpiJob> mpiJobs(const Application& application, const Catalog& catalog) {
  std::vector<MpiJob> jobs;
  std::map<std::tuple<std::string, std::string, std::string>, std::size_t> byKey;
  for (std::size_t m = 0; m < application.modules.size(); ++m) {
    const Module& module = application.modules[m];
    const ModuleType* type = catalog.findModule(module.package, module.type);
    if (type == nullptr || type->mpiJobParam.empty()) continue;
    std::string name = effectiveParamValue(module, *type, type->mpiJobParam);
    if (name.empty()) continue;
    const auto [it, added] =
        byKey.emplace(std::make_tuple(module.package, module.type, name), jobs.size());
    if (added) jobs.push_back(MpiJob{std::move(name), module.package, module.type, {}});
    jobs[it->second].modules.push_back(m);
  }
  return jobs;
}

}  // namespace vrflow::app
