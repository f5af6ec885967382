#include <nlohmann/json.hpp>

#include "vrflow/launcher/launch.hpp"
#include "vrflow/run/report_head.hpp"

namespace vrflow::launcher {

std::string mergeReports(const app::Application& application, const std::vector<std::string>& parts,
                         const run::RunOutcome& outcome, uint64_t iterations, double wallSeconds) {
  using nlohmann::ordered_json;
  std::vector<ordered_json> shares;
  for (const auto& p : parts) {
    auto j = ordered_json::parse(p, nullptr, false);
    if (!j.is_discarded() && j.is_object()) shares.push_back(std::move(j));
  }
  auto collect = [&](const char* key) {
    std::vector<ordered_json> all;
    for (const auto& s : shares) {
      if (s.contains(key) && s[key].is_array()) {
        for (const auto& item : s[key]) all.push_back(item);
      }
    }
    return all;
  };
  // File order, as `vrflow run` reports.
  auto moduleRank = [&](const std::string& id) {
    for (std::size_t i = 0; i < application.modules.size(); ++i) {
      if (application.modules[i].id == id) return i;
    }
    return application.modules.size();
  };
  auto connectionRank = [&](const ordered_json& c) {
    for (std::size_t i = 0; i < application.connections.size(); ++i) {
      const auto& k = application.connections[i];
      if (app::toString(k.from) == c.value("from", "") &&
          app::toString(k.to) == c.value("to", "")) {
        return i;
      }
    }
    return application.connections.size();
  };
  auto modules = collect("modules");
  std::stable_sort(modules.begin(), modules.end(), [&](const auto& a, const auto& b) {
    return moduleRank(a.value("id", "")) < moduleRank(b.value("id", ""));
  });
  auto connections = collect("connections");
  std::stable_sort(connections.begin(), connections.end(), [&](const auto& a, const auto& b) {
    return connectionRank(a) < connectionRank(b);
  });
  auto outputs = collect("outputs");
  std::stable_sort(outputs.begin(), outputs.end(), [&](const auto& a, const auto& b) {
    return moduleRank(a.value("module", "")) < moduleRank(b.value("module", ""));
  });
  // As `vrflow run` orders them: the modules' input filters ("module.port") in module order,
  // then the application's filters in file order.
  auto filterRank = [&](const ordered_json& f) -> std::size_t {
    const std::string id = f.value("id", "");
    if (const auto dot = id.find('.'); dot != std::string::npos)
      return moduleRank(id.substr(0, dot));
    for (std::size_t i = 0; i < application.filters.size(); ++i) {
      if (application.filters[i].id == id) return application.modules.size() + 1 + i;
    }
    return application.modules.size() + 1 + application.filters.size();
  };
  auto filters = collect("filters");
  std::stable_sort(filters.begin(), filters.end(),
                   [&](const auto& a, const auto& b) { return filterRank(a) < filterRank(b); });
  ordered_json report = run::reportHead(application, outcome, iterations);
  report["modules"] = modules;
  report["connections"] = connections;
  report["filters"] = filters;
  report["outputs"] = outputs;
  ordered_json warnings = ordered_json::array();
  ordered_json hosts = ordered_json::array();
  uint64_t peak = 0;
  for (const auto& s : shares) {
    if (s.contains("warnings")) {
      for (const auto& w : s["warnings"]) warnings.push_back(w);
    }
    if (s.contains("timing") && s["timing"].contains("segment_peak_bytes")) {
      peak = std::max<uint64_t>(peak, s["timing"]["segment_peak_bytes"].get<uint64_t>());
    }
  }
  report["warnings"] = warnings;
  ordered_json timing;
  timing["wall_s"] = wallSeconds;
  timing["segment_peak_bytes"] = peak;
  timing["hosts"] = shares.size();
  report["timing"] = timing;
  return report.dump(2);
}

}  // namespace vrflow::launcher
