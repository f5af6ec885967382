#include "test_support.hpp"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "vrflow/app/validate.hpp"
#include "vrflow/daemon/filter_registry.hpp"

namespace vrflow::app::testing {

std::string sourceDir() {
  if (const char* dir = std::getenv("VRFLOW_SOURCE_DIR")) return dir;
  return VRFLOW_TEST_SOURCE_DIR;
}

std::string dataDir() {
  return sourceDir() + "/tests/app/data";
}

const Catalog& testCatalog() {
  static const Catalog catalog = [] {
    Catalog loaded = daemon::makeCatalog();
    const Status status = loaded.addPackageDir(dataDir() + "/packages");
    if (!status) throw std::runtime_error(status.error().message);
    return loaded;
  }();
  return catalog;
}

std::vector<Diagnostic> check(std::string_view xml) {
  return checkApplicationString(xml, "app.xml", testCatalog());
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

}  // namespace vrflow::app::testing
