#pragma once

// The first fields of a run report, shared by `vrflow run` (run/report.cpp) and the report
// `vrflow launch` merges from the hosts' shares (launcher/src/merge_reports.cpp).

#include <cstdint>
#include <nlohmann/json.hpp>

#include "vrflow/app/model.hpp"
#include "vrflow/run/runner.hpp"

namespace vrflow::run {

/// The report's leading fields, in their order: format, vrflow_version, application, file,
/// status, exit_code, error, iterations_requested (docs/report.md).
nlohmann::ordered_json reportHead(const app::Application& application, const RunOutcome& outcome,
                                  uint64_t iterationsRequested);

}  // namespace vrflow::run
