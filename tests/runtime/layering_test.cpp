// The layering as the dynamic linker sees it (docs/architecture.md): a module executable needs
// libvrflow_module and no other vrflow library.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "process_helpers.hpp"

namespace fs = std::filesystem;
using vrflow::testing::binDir;
using vrflow::testing::runCommand;

namespace {

// The executables named by every package manifest of the build (share/ and test-packages/).
std::set<fs::path> moduleExecutables() {
  std::set<fs::path> found;
  const fs::path bin = binDir();
  const std::regex executable("executable=\"([^\"]+)\"");
  for (const fs::path& root :
       {bin / ".." / "share" / "vrflow" / "packages", bin / ".." / "test-packages"}) {
    std::error_code ec;
    for (const auto& entry : fs::recursive_directory_iterator(root, ec)) {
      if (entry.path().filename() != "vrflow-package.xml") continue;
      std::ifstream in(entry.path());
      std::stringstream text;
      text << in.rdbuf();
      const std::string manifest = text.str();
      for (std::sregex_iterator it(manifest.begin(), manifest.end(), executable), end; it != end;
           ++it) {
        const fs::path file = bin / fs::path((*it)[1].str()).filename();
        if (fs::exists(file)) found.insert(file);
      }
    }
  }
  return found;
}

// The vrflow libraries `ldd` lists for `file`.
std::set<std::string> vrflowLibraries(const fs::path& file) {
  const auto result = runCommand({"/usr/bin/ldd", file.string()});
  EXPECT_EQ(result.exitCode, 0) << file << ": " << result.err;
  std::set<std::string> libraries;
  std::istringstream lines(result.out);
  for (std::string line; std::getline(lines, line);) {
    const auto start = line.find("libvrflow");
    if (start == std::string::npos) continue;
    libraries.insert(line.substr(start, line.find_first_of(" \t", start) - start));
    EXPECT_EQ(line.find("not found"), std::string::npos) << file << ": " << line;
  }
  return libraries;
}

}  // namespace

TEST(Layering, ModuleExecutablesLinkOnlyTheModuleLibrary) {
  const auto executables = moduleExecutables();
  // The core package alone has six modules; the test packages more.
  ASSERT_GE(executables.size(), 6u);
  for (const auto& file : executables) {
    EXPECT_EQ(vrflowLibraries(file), std::set<std::string>{"libvrflow_module.so.0"}) << file;
  }
}

TEST(Layering, TheProgramsLinkTheLayersAsSharedLibraries) {
  const auto libraries = vrflowLibraries(fs::path(binDir()) / "vrflow");
  for (const char* layer :
       {"libvrflow_module.so.0", "libvrflow_app.so.0", "libvrflow_net.so.0",
        "libvrflow_daemon.so.0", "libvrflow_run.so.0", "libvrflow_launcher.so.0"}) {
    EXPECT_TRUE(libraries.count(layer)) << "vrflow does not link " << layer;
  }
}
