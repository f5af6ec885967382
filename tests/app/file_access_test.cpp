// Files the application model reads by name (application, manifest, composite) come only from
// regular files up to a size cap; the checks of file parameters declared input or output; values
// echoed in diagnostics are bounded.
#include "vrflow/base/file_access.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>

#include "test_support.hpp"
#include "vrflow/app/app.hpp"
#include "vrflow/base/echo.hpp"
#include "vrflow/base/executable_dir.hpp"
#include "vrflow/daemon/filter_registry.hpp"

namespace vrflow::app {
namespace {

namespace fs = std::filesystem;

// A fresh folder under the system's temporary folder, removed with its contents.
class ScratchDir {
 public:
  ScratchDir() {
    std::string pattern = (fs::temp_directory_path() / "vrflow-files-XXXXXX").string();
    path_ = mkdtemp(pattern.data()) != nullptr ? pattern : "";
  }
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

// Runs `load` on a thread; when it has not returned after 20 s (it waits on a FIFO), opens the
// FIFO for writing to release it, and fails.
std::string loadWithHangGuard(const std::string& fifo, std::function<std::string()> load) {
  auto result = std::async(std::launch::async, std::move(load));
  if (result.wait_for(std::chrono::seconds(20)) != std::future_status::ready) {
    const int writer = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (writer >= 0) ::close(writer);
    ADD_FAILURE() << "reading the FIFO " << fifo << " blocked for 20 s";
  }
  return result.get();
}

std::string errorOf(const Status& status) {
  return status ? "(no error)" : status.error().message;
}
template <typename T>
std::string errorOf(const Result<T>& result) {
  return result ? "(no error)" : result.error().message;
}

TEST(FileReading, ApplicationFromDevZeroIsRefusedWithoutReadingIt) {
  const auto loaded = loadApplicationFile("/dev/zero");
  EXPECT_EQ(errorOf(loaded),
            "/dev/zero: error: cannot read file (it is a character device, not a regular file)");
}

TEST(FileReading, ApplicationManifestAndCompositeFromAFifoAreRefusedWithoutBlocking) {
  ScratchDir dir;
  const std::string fifo = dir.file("app.xml");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string expected =
      fifo + ": error: cannot read file (it is a FIFO, not a regular file)";
  EXPECT_EQ(loadWithHangGuard(fifo, [&] { return errorOf(loadApplicationFile(fifo)); }), expected);
  EXPECT_EQ(loadWithHangGuard(fifo,
                              [&] {
                                Catalog catalog = daemon::makeCatalog();
                                return errorOf(catalog.addPackageFile(fifo));
                              }),
            expected);
  EXPECT_EQ(loadWithHangGuard(fifo, [&] { return errorOf(loadCompositeFile(fifo)); }), expected);
  const auto checked = loadWithHangGuard(
      fifo, [&] { return formatDiagnostics(checkApplicationFile(fifo, testing::testCatalog())); });
  EXPECT_EQ(checked, expected + "\n");
}

TEST(FileReading, DirectoryIsRefusedAsADirectory) {
  ScratchDir dir;
  const std::string folder = dir.file("app.xml");
  fs::create_directory(folder);
  EXPECT_EQ(errorOf(loadApplicationFile(folder)),
            folder + ": error: cannot read file (it is a directory, not a regular file)");
  EXPECT_EQ(errorOf(loadCompositeFile(folder)),
            folder + ": error: cannot read file (it is a directory, not a regular file)");
}

TEST(FileReading, SparseFileAboveTheCapIsRefusedBeforeItIsRead) {
  ScratchDir dir;
  const std::string big = dir.file("big.xml");
  { std::ofstream(big) << "<application name=\"a\" version=\"1\">"; }
  fs::resize_file(big, std::uintmax_t{1} << 30);  // 1 GiB, sparse
  const std::string expected = big +
                               ": error: cannot read file (it is 1073741824 bytes, above the "
                               "limit of 16777216 bytes (16 MiB))";
  EXPECT_EQ(errorOf(loadApplicationFile(big)), expected);
  Catalog catalog = daemon::makeCatalog();
  EXPECT_EQ(errorOf(catalog.addPackageFile(big)), expected);
  EXPECT_EQ(errorOf(loadCompositeFile(big)), expected);
}

TEST(FileReading, RegularFileAtTheCapIsReadWhole) {
  ScratchDir dir;
  const std::string file = dir.file("data");
  { std::ofstream(file) << std::string(1000, 'x'); }
  const auto content = readRegularFile(file, 1000);
  ASSERT_TRUE(content) << content.error().message;
  EXPECT_EQ(content->size(), 1000u);
  EXPECT_EQ(errorOf(readRegularFile(file, 999)),
            "cannot read file (it is 1000 bytes, above the limit of 999 bytes)");
}

// --- File parameters declared input or output ---

constexpr std::string_view kFilesManifest = R"(<package name="files">
  <module type="reader" executable="/bin/true">
    <param name="in" type="file" access="input" default=""/>
    <param name="out" type="file" access="output" default="out.csv"/>
    <param name="free" type="file" default=""/>
  </module>
</package>
)";

const Catalog& filesCatalog() {
  static const Catalog catalog = [] {
    Catalog c = daemon::makeCatalog();
    EXPECT_TRUE(c.addPackageString(kFilesManifest, "/pkg/files/vrflow-package.xml").ok());
    return c;
  }();
  return catalog;
}

std::vector<Diagnostic> checkReader(const std::string& in, const std::string& out,
                                    const std::string& free = "") {
  Application app;
  app.hosts.push_back(Host{"localhost", "127.0.0.1", {}});
  Module module;
  module.id = "r";
  module.package = "files";
  module.type = "reader";
  module.host = "localhost";
  module.params = {Param{"in", in, {}}, Param{"out", out, {}}, Param{"free", free, {}}};
  app.modules.push_back(module);
  return checkModuleFiles(app, filesCatalog());
}

TEST(FileParameters, ManifestStatesInputAndOutput) {
  const ModuleType* reader = filesCatalog().findModule("files", "reader");
  ASSERT_NE(reader, nullptr);
  EXPECT_EQ(reader->findParam("in")->access, FileAccess::Input);
  EXPECT_EQ(reader->findParam("out")->access, FileAccess::Output);
  EXPECT_EQ(reader->findParam("free")->access, FileAccess::Unstated);
}

TEST(FileParameters, AccessIsOnlyForFileParametersAndOnlyInputOrOutput) {
  Catalog catalog = daemon::makeCatalog();
  const Status status = catalog.addPackageString(R"(<package name="p">
  <module type="m" executable="x">
    <param name="a" type="string" access="input"/>
    <param name="b" type="file" access="both"/>
  </module>
</package>
)",
                                                 "pkg.xml");
  EXPECT_EQ(errorOf(status),
            "pkg.xml:3:35: error: attribute 'access' applies only to file parameters\n"
            "pkg.xml:4:33: error: attribute 'access' of <param> must be one of input, output, "
            "got 'both'");
}

TEST(FileParameters, InputMustBeARegularFile) {
  ScratchDir dir;
  const std::string data = dir.file("data.txt");
  std::ofstream(data) << "x";
  EXPECT_TRUE(checkReader(data, "out.csv").empty()) << formatDiagnostics(checkReader(data, ""));
  const auto device = checkReader("/dev/zero", "");
  ASSERT_EQ(device.size(), 1u);
  EXPECT_EQ(device[0].message,
            "parameter 'in' of module 'r' (files/reader) names '/dev/zero', an input that must be "
            "a regular file (it is a character device, not a regular file)");
  const auto folder = checkReader(dir.file(""), "");
  ASSERT_EQ(folder.size(), 1u);
  EXPECT_NE(folder[0].message.find("(it is a directory, not a regular file)"), std::string::npos);
  const auto missing = checkReader(dir.file("missing.txt"), "");
  ASSERT_EQ(missing.size(), 1u);
  EXPECT_NE(missing[0].message.find("(No such file or directory)"), std::string::npos);
}

TEST(FileParameters, OutputFolderMustExistOutsideTheWorkingFolder) {
  ScratchDir dir;
  EXPECT_TRUE(checkReader("", dir.file("x.csv")).empty());
  EXPECT_TRUE(checkReader("", "results/today/x.csv").empty());  // created by the module
  EXPECT_TRUE(checkReader("", "/dev/null").empty());
  const auto outside = checkReader("", dir.file("missing/dir/x.csv"));
  ASSERT_EQ(outside.size(), 1u);
  EXPECT_EQ(outside[0].message,
            "parameter 'out' of module 'r' (files/reader) names '" + dir.file("missing/dir/x.csv") +
                "', an output that cannot be written: folder '" + dir.file("missing/dir") +
                "' does not exist (folders are created only inside the run's working folder; "
                "create it first)");
  EXPECT_EQ(checkReader("", "../escaped/x.csv").size(), 1u);
  EXPECT_FALSE(fs::exists(dir.file("missing")));
  EXPECT_TRUE(checkReader("", "", "/dev/zero").empty());  // access unstated: not checked
}

TEST(FileParameters, PrepareOutputPathCreatesFoldersOnlyInsideTheWorkingFolder) {
  ScratchDir dir;
  const Status outside = prepareOutputPath(dir.file("a/b/x.csv"));
  EXPECT_FALSE(outside.ok());
  EXPECT_FALSE(fs::exists(dir.file("a")));
  const fs::path before = fs::current_path();
  fs::current_path(dir.file(""));
  const Status inside = prepareOutputPath("a/b/x.csv");
  fs::current_path(before);
  EXPECT_TRUE(inside.ok()) << errorOf(inside);
  EXPECT_TRUE(fs::is_directory(dir.file("a/b")));
}

// --- Executables ---

// A manifest under `folder` declaring module type "m" with `executable`, and an
// application with one module "m1" of it.
std::string writeManifest(const std::string& folder, const std::string& executable) {
  fs::create_directories(folder);
  const std::string manifest = folder + "/vrflow-package.xml";
  std::ofstream(manifest) << "<package name=\"pkg\">\n  <module type=\"m\" executable=\"" +
                                 executable + "\"/>\n</package>\n";
  return manifest;
}

Application oneModuleOf(const std::string& package, const std::string& type) {
  Application app;
  app.hosts.push_back(Host{"localhost", "127.0.0.1", {}});
  Module module;
  module.id = "m1";
  module.package = package;
  module.type = type;
  module.host = "localhost";
  app.modules.push_back(module);
  return app;
}

// Module type "m" of the manifest written by writeManifest(), read into `catalog`; nullptr when
// the manifest does not load.
const ModuleType* readModuleType(Catalog& catalog, const std::string& manifest) {
  return catalog.addPackageFile(manifest).ok() ? catalog.findModule("pkg", "m") : nullptr;
}

void writeProgram(const std::string& path) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path) << "#!/bin/sh\n";
  fs::permissions(path, fs::perms::owner_all);
}

TEST(Executables, RelativePathIsResolvedFromTheManifestFolderEvenWhenMissing) {
  ScratchDir dir;
  const std::string manifest = writeManifest(dir.file("share/pkg"), "../../bin/x");
  Catalog catalog;
  const ModuleType* type = readModuleType(catalog, manifest);
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(type->executable, dir.file("bin/x"));

  const Application app = oneModuleOf("pkg", "m");
  const auto problems = checkModuleFiles(app, catalog, ModuleFileChecks{.executables = true});
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].message, "module 'm1' (pkg/m): cannot start its executable '" +
                                     dir.file("bin/x") +
                                     "' (No such file or directory), resolved from " + manifest +
                                     ":2 against the manifest's folder");
  EXPECT_TRUE(checkModuleFiles(app, catalog).empty());  // validate does not ask for it
}

// A manifest in `folder` naming `executable`, with a program at `program`: the module type's
// executable is `program`, and `vrflow run`'s check of executables passes.
void expectResolvedAndStartable(const std::string& folder, const std::string& executable,
                                const std::string& program) {
  const std::string manifest = writeManifest(folder, executable);
  writeProgram(program);
  Catalog catalog;
  const ModuleType* type = readModuleType(catalog, manifest);
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(type->executable, program);
  EXPECT_TRUE(
      checkModuleFiles(oneModuleOf("pkg", "m"), catalog, ModuleFileChecks{.executables = true})
          .empty());
}

TEST(Executables, BareNameIsFoundInTheBinFolderOfTheBuildTree) {
  // The build tree has an install's shape: build/share/vrflow/packages/core/ and build/bin.
  const fs::path bin = executableDir();
  ASSERT_FALSE(bin.empty());
  const std::string manifest =
      (bin.parent_path() / "share/vrflow/packages/core/vrflow-package.xml").string();
  Catalog catalog;
  ASSERT_TRUE(catalog.addPackageFile(manifest).ok());
  const ModuleType* source = catalog.findModule("core", "source");
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->executable, (bin / "vrflow-core-source").string());
  EXPECT_TRUE(source->executableSearched.empty());
  EXPECT_TRUE(checkModuleFiles(oneModuleOf("core", "source"), catalog,
                               ModuleFileChecks{.executables = true})
                  .empty());
}

TEST(Executables, BareNameIsFoundInTheBinFolderOfAnInstalledLayout) {
  ScratchDir prefix;
  expectResolvedAndStartable(prefix.file("share/vrflow/packages/pkg"), "tool",
                             prefix.file("bin/tool"));
}

TEST(Executables, BareNameInThePackagesFolderComesBeforeTheLayoutsBin) {
  ScratchDir prefix;
  const std::string manifest = writeManifest(prefix.file("share/vrflow/packages/pkg"), "tool");
  writeProgram(prefix.file("bin/tool"));
  writeProgram(prefix.file("share/vrflow/packages/pkg/tool"));
  Catalog catalog;
  const ModuleType* type = readModuleType(catalog, manifest);
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(type->executable, prefix.file("share/vrflow/packages/pkg/tool"));
}

TEST(Executables, MissingBareNameNamesTheManifestLineAndTheFoldersLookedIn) {
  ScratchDir prefix;
  const std::string manifest = writeManifest(prefix.file("share/vrflow/packages/pkg"), "absent");
  Catalog catalog;
  ASSERT_TRUE(catalog.addPackageFile(manifest).ok());  // reading a catalog needs no build
  const ModuleType* type = catalog.findModule("pkg", "m");
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(type->executable, "absent");
  const Application app = oneModuleOf("pkg", "m");
  const auto problems = checkModuleFiles(app, catalog, ModuleFileChecks{.executables = true});
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].message,
            "module 'm1' (pkg/m): no executable 'absent' (declared at " + manifest +
                ":2) in the package's folder, its layout's bin folder or beside this program; "
                "looked in " +
                prefix.file("share/vrflow/packages/pkg") + ", " + prefix.file("bin") + ", " +
                executableDir().lexically_normal().string());
  EXPECT_TRUE(checkModuleFiles(app, catalog).empty());  // validate does not ask for it
}

TEST(Executables, BareNameOutsideAnInstalledLayoutSkipsTheLayoutsBin) {
  ScratchDir dir;
  const std::string manifest = writeManifest(dir.file("pkg"), "absent");
  writeProgram(dir.file("bin/absent"));  // ../bin of an ordinary folder is not a layout's bin
  Catalog catalog;
  const ModuleType* type = readModuleType(catalog, manifest);
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(type->executable, "absent");
  const std::vector<std::string> expected{dir.file("pkg"),
                                          executableDir().lexically_normal().string()};
  EXPECT_EQ(type->executableSearched, expected);
}

TEST(Executables, PathWithASlashStaysRelativeToTheManifest) {
  ScratchDir dir;
  expectResolvedAndStartable(dir.file("pkg"), "tools/x", dir.file("pkg/tools/x"));
}

// --- Echoed values ---

TEST(EchoedValues, LongQuotedValueIsCutWithItsLength) {
  const std::string value(100000, 'a');
  EXPECT_EQ(quotedValue(value), "'" + std::string(kMaxEchoedBytes, 'a') + "\u2026(100000 bytes)'");
  EXPECT_EQ(quotedValue("short"), "'short'");
  const Diagnostic diagnostic{SourceLocation{"app.xml", 3, 5}, Diagnostic::Error,
                              "unknown module type '" + value + "' (the module's type)"};
  EXPECT_EQ(formatDiagnostic(diagnostic), "app.xml:3:5: error: unknown module type '" +
                                              std::string(kMaxEchoedBytes, 'a') +
                                              "\u2026(100000 bytes)' (the module's type)");
}

TEST(EchoedValues, CutNeverSplitsAUtf8Character) {
  std::string text;
  for (int i = 0; i < 100; ++i) text += "\xC3\xA9";  // 'é' twice a byte: 200 bytes
  const std::string cut = quotedValue(text);
  EXPECT_EQ(cut, "'" + text.substr(0, kMaxEchoedBytes) + "\u2026(200 bytes)'");
  const std::string odd = "x" + text;  // the cut falls inside a character: it backs off
  EXPECT_EQ(quotedValue(odd), "'" + odd.substr(0, kMaxEchoedBytes - 1) + "\u2026(201 bytes)'");
}

TEST(EchoedValues, MessageIsBoundedWhateverItsQuotes) {
  const std::string message = "it's " + std::string(100000, 'b');
  const std::string bounded = boundMessage(message);
  EXPECT_LE(bounded.size(), kMaxMessageBytes + 32);
  EXPECT_NE(bounded.find("(100005 bytes)"), std::string::npos);
}

TEST(EchoedValues, LoadingAFileWithAHugeValueGivesABoundedError) {
  const std::string id(10 << 20, 'i');  // a 10 MB id
  std::vector<Diagnostic> problems;
  const std::string xml = R"(<application name="a" version="1"><modules><module id=")" + id +
                          R"(" package="core" type="source"/></modules>)"
                          R"(<connections><connection from="a.out" to=")" +
                          id + R"(.in"/></connections></application>)";
  const auto found = checkApplicationString(xml, "app.xml", testing::testCatalog());
  const std::string text = formatDiagnostics(found);
  ASSERT_FALSE(found.empty());
  EXPECT_LT(text.size(), 16384u) << text.substr(0, 2000);
  EXPECT_NE(text.find("(10485760 bytes)"), std::string::npos) << text.substr(0, 2000);
}

}  // namespace
}  // namespace vrflow::app
