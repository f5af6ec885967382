// Every example's README runs as written: its indented command blocks are read from the README
// and run from a folder shaped like the repository root (build/ and examples/ in it), so a
// README that drifts from the code fails here. Long runs are cut to a few iterations.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <sstream>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

/// Examples whose README is not run here, and why.
const std::vector<std::pair<std::string, std::string>> kNotRun = {
    {"minimal_module", "builds a module out of tree: the install tests run its README"},
    {"filter_plugin", "builds a plugin out of tree: the install tests run its README"},
};

/// Lines of a README block that are not run, and why.
const std::vector<std::pair<std::string, std::string>> kSkippedCommands = {
    {"ffmpeg", "needs ffmpeg and the viewer's videos (routed_wall)"},
    {"cd routed-wall", "only to run ffmpeg on the videos (routed_wall)"},
    {"build/bin/vrflow-bench-patterns", "a benchmark (bench/patterns runs it)"},
    {"../../build/bin/vrflow run ../../examples/interactive/interactive_window.xml",
     "opens a window for a person's mouse (tests/input runs it under Xvfb)"},
};

constexpr int kMaxIterations = 20;

bool isCommand(const std::string& line) {
  static const std::regex command(R"(^(cd |mkdir |(\.\./)*build/bin/vrflow ))");
  return std::regex_search(line, command);
}

bool isSkipped(const std::string& line) {
  return std::any_of(kSkippedCommands.begin(), kSkippedCommands.end(),
                     [&](const auto& skip) { return line.rfind(skip.first, 0) == 0; });
}

// `-n N` and `--iterations N` above kMaxIterations become kMaxIterations.
std::string withFewIterations(const std::string& line) {
  static const std::regex iterations(R"((-n|--iterations) ([0-9]+))");
  std::string out;
  std::size_t last = 0;
  for (auto it = std::sregex_iterator(line.begin(), line.end(), iterations);
       it != std::sregex_iterator(); ++it) {
    const std::smatch& match = *it;
    out += line.substr(last, static_cast<std::size_t>(match.position(0)) - last);
    const int count = std::stoi(match[2].str());
    out += match[1].str() + " " + std::to_string(std::min(count, kMaxIterations));
    last = static_cast<std::size_t>(match.position(0) + match.length(0));
  }
  return out + line.substr(last);
}

/// The README's command blocks: runs of lines indented by four spaces outside ``` fences,
/// continuation lines joined, keeping the blocks that hold a command.
std::vector<std::vector<std::string>> commandBlocks(const std::string& readme) {
  std::vector<std::vector<std::string>> blocks;
  std::vector<std::string> block;
  bool fenced = false;
  std::istringstream in(readme);
  auto endBlock = [&] {
    if (std::any_of(block.begin(), block.end(), isCommand)) blocks.push_back(block);
    block.clear();
  };
  std::string pending;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("```", 0) == 0) fenced = !fenced;
    if (fenced || line.rfind("    ", 0) != 0) {
      endBlock();
      continue;
    }
    std::string text = line.substr(4);
    // A continuation line's indentation is not part of the command.
    if (!pending.empty()) text.erase(0, text.find_first_not_of(' '));
    if (!text.empty() && text.back() == '\\') {
      pending += text.substr(0, text.size() - 1);
      continue;
    }
    block.push_back(pending + text);
    pending.clear();
  }
  endBlock();
  return blocks;
}

// A node package that an application file of examples/<example> uses and this build lacks
// (the sanitizer builds leave the node packages out); empty when it has them all.
std::string missingNodePackage(const std::string& example) {
  for (const auto& entry :
       std::filesystem::directory_iterator(sourceDir() + "/examples/" + example)) {
    if (entry.path().extension() != ".xml") continue;
    const std::string text = readFile(entry.path().string());
    for (const char* package : {"rigid", "massspring", "fluid", "viewer"}) {
      const bool used = text.find("package=\"" + std::string(package) + "\"") != std::string::npos;
      if (used && !std::filesystem::exists(binDir() + "/../share/vrflow/packages/" + package)) {
        return package;
      }
    }
  }
  return {};
}

// True when the example's own package declares Python script modules (script="...").
bool usesPythonModules(const std::string& example) {
  const std::string manifest = sourceDir() + "/examples/" + example + "/vrflow-package.xml";
  return std::filesystem::exists(manifest) &&
         readFile(manifest).find("script=\"") != std::string::npos;
}

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

class ExampleReadme : public ::testing::TestWithParam<std::string> {};

TEST_P(ExampleReadme, CommandsRunAsWrittenFromTheRepositoryRoot) {
  const std::string example = GetParam();
  const auto blocks = commandBlocks(readFile(sourceDir() + "/examples/" + example + "/README.md"));
  ASSERT_FALSE(blocks.empty()) << "no command in examples/" << example << "/README.md";
  if (const std::string missing = missingNodePackage(example); !missing.empty()) {
    GTEST_SKIP() << "this build has no node package '" << missing << "' (VRFLOW_NODES=OFF)";
  }
  if (kSanitized && usesPythonModules(example)) {
    GTEST_SKIP() << "Python modules: the interpreter cannot load the sanitized vrflow._module "
                    "(the sanitizer's runtime must come first in the process)";
  }
  TempDir root;
  std::filesystem::create_directory_symlink(std::filesystem::path(binDir()).parent_path(),
                                            root.file("build"));
  std::filesystem::create_directory_symlink(sourceDir() + "/examples", root.file("examples"));
  for (const auto& block : blocks) {
    std::string script = "set -e\ncd " + root.path() + "\n";
    for (const std::string& line : block) {
      if (!isSkipped(line)) script += withFewIterations(line) + "\n";
    }
    const auto ran = runCommand({"/bin/bash", "-c", script}, 240);
    EXPECT_EQ(ran.exitCode, 0) << script << "\n" << ran.err;
    std::vector<std::string> left = leftoverProcesses();
    EXPECT_TRUE(left.empty()) << script << "\n" << left.front();
  }
}

std::vector<std::string> examplesWithAReadme() {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(sourceDir() + "/examples")) {
    const std::string name = entry.path().filename().string();
    const bool notRun = std::any_of(kNotRun.begin(), kNotRun.end(),
                                    [&](const auto& skip) { return skip.first == name; });
    if (!notRun && std::filesystem::is_regular_file(entry.path() / "README.md")) {
      names.push_back(name);
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

INSTANTIATE_TEST_SUITE_P(Examples, ExampleReadme, ::testing::ValuesIn(examplesWithAReadme()),
                         [](const ::testing::TestParamInfo<std::string>& example) {
                           return example.param;
                         });

TEST(ExampleReadmes, ReaderJoinsContinuationLinesAndCutsIterations) {
  const auto blocks = commandBlocks(
      "Text\n\n    mkdir -p out/x && cd out/x\n    ../../build/bin/vrflow run a.xml -n 300 \\\n"
      "        --report r.json\n\n    a diagram line\n\n```sh\n    build/bin/vrflow run b\n```\n");
  ASSERT_EQ(blocks.size(), 1u);
  ASSERT_EQ(blocks[0].size(), 2u);
  EXPECT_EQ(blocks[0][1], "../../build/bin/vrflow run a.xml -n 300 --report r.json");
  EXPECT_EQ(withFewIterations(blocks[0][1]),
            "../../build/bin/vrflow run a.xml -n 20 --report r.json");
  EXPECT_EQ(withFewIterations("vrflow run a.xml --iterations 5"),
            "vrflow run a.xml --iterations 5");
}

}  // namespace
}  // namespace vrflow::testing
