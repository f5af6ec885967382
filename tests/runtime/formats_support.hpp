#pragma once

// What the tests of versions, formats and progress share: the run report's JSON Schema
// (runtime/schema/vrflow-report.schema.json) checked by a real validator (python3-jsonschema
// through tests/runtime/check_report_schema.py), and a small pipeline to run.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "app_text.hpp"
#include "process_helpers.hpp"

namespace vrflow::testing {

/// source -> relay -> recorder on one host, written to `dir`/app.xml; the relay is of type
/// `relay` ("package/type"), with `relayInner` (its <param> lines).
inline std::string relayPipeline(const TempDir& dir, const std::string& relay = "core/relay",
                                 const std::string& relayInner = "") {
  return dir.write(
      "app.xml",
      appXml(moduleXml("source", "core/source") + moduleXml("relay", relay, relayInner) +
                 moduleXml("recorder", "core/recorder", paramXml("file", dir.file("rec.csv"))),
             "", connectXml("source.out", "relay.in") + connectXml("relay.out", "recorder.in")));
}

/// Validates the report at `path`: exit code 0 when valid, else 1 with each violation on stdout.
inline CommandResult validateReport(const std::string& path) {
  return runCommand({"/usr/bin/python3", sourceDir() + "/tests/runtime/check_report_schema.py",
                     sourceDir() + "/runtime/schema/vrflow-report.schema.json", path});
}

/// The report at `path`, checked against the schema first (the test fails naming each violation).
inline nlohmann::json checkedReport(const std::string& path) {
  const auto valid = validateReport(path);
  EXPECT_EQ(valid.exitCode, 0) << valid.out << valid.err;
  return nlohmann::json::parse(readFile(path));
}

}  // namespace vrflow::testing
