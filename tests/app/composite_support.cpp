#include "composite_support.hpp"

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vrflow/app/loader.hpp"

namespace vrflow::app::testing {

std::string compositeDir() {
  return dataDir() + "/composites";
}

CompositeSources testCompositeSources() {
  CompositeSources sources;
  sources.searchPath.push_back(compositeDir());
  return sources;
}

Application expandOrFail(std::string_view xml) {
  Result<Application> app = loadApplicationString(xml, "app.xml");
  EXPECT_TRUE(app.ok()) << app.error().message;
  if (!app) return {};
  Result<Application> flat = expandComposites(*app, testCompositeSources());
  EXPECT_TRUE(flat.ok()) << flat.error().message;
  return flat ? std::move(flat).value() : Application{};
}

std::vector<Diagnostic> checkComposed(std::string_view xml) {
  std::vector<Diagnostic> problems;
  Result<Application> app = loadApplicationString(xml, "app.xml", &problems);
  if (!app) return {Diagnostic{{}, Diagnostic::Error, app.error().message}};
  std::vector<Diagnostic> more =
      validateWithComposites(*app, testCatalog(), testCompositeSources());
  problems.insert(problems.end(), more.begin(), more.end());
  sortAndDeduplicate(problems);
  return problems;
}

std::vector<std::string> nodeIds(const Application& app) {
  std::vector<std::string> ids;
  for (const Module& module : app.modules) ids.push_back(module.id);
  for (const Filter& filter : app.filters) ids.push_back(filter.id);
  return ids;
}

std::vector<std::string> connectionTexts(const Application& app) {
  std::vector<std::string> texts;
  for (const Connection& connection : app.connections) {
    texts.push_back(toString(connection.from) + " -> " + toString(connection.to));
  }
  return texts;
}

}  // namespace vrflow::app::testing
