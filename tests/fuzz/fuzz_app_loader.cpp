// libFuzzer target for the application model: load any text as an application file, validate
// it against a small catalog, save it, and check that saving is stable (load(save(x)) saves to
// the same bytes). Also reads the same text as a package manifest. Must never crash or hang.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/app.hpp"

namespace {

constexpr std::string_view kManifest = R"(<package name="core" version="1">
  <module type="source" executable="vrflow-core-source" kind="input">
    <output name="out" data="numbers"/>
    <param name="count" type="int" default="0" min="0" max="10"/>
    <param name="rate" type="float" default="60" min="0.5"/>
    <param name="mode" type="enum" default="fast" choices="fast,slow"/>
    <param name="offset" type="vec3" default="0 0 0"/>
    <param name="verbose" type="bool" default="false"/>
  </module>
  <module type="sink" executable="vrflow-core-sink">
    <input name="in" data="numbers" required="true"/>
  </module>
  <module type="relay" executable="vrflow-core-relay">
    <input name="in"/>
    <output name="out"/>
  </module>
  <module type="animator" executable="vrflow-animator" kind="animator">
    <input name="events" data="events"/>
    <output name="objects" data="objects"/>
  </module>
  <module type="interactor" executable="vrflow-interactor" kind="interactor">
    <input name="objects" data="objects" required="true"/>
    <output name="forces" data="events"/>
  </module>
</package>
)";

const vrflow::app::Catalog& catalog() {
  static const vrflow::app::Catalog loaded = [] {
    vrflow::app::Catalog c;
    const vrflow::Status status = c.addPackageString(kManifest, "/fuzz/vrflow-package.xml");
    if (!status) {
      std::fprintf(stderr, "fuzz catalog: %s\n", status.error().message.c_str());
      std::abort();
    }
    return c;
  }();
  return loaded;
}

}  // namespace

// NOLINTNEXTLINE(readability-identifier-naming): the name libFuzzer calls
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace vrflow::app;
  const std::string_view xml(reinterpret_cast<const char*>(data), size);

  std::vector<Diagnostic> problems;
  const vrflow::Result<Application> app = loadApplicationString(xml, "fuzz.xml", &problems);
  if (app.ok()) {
    const std::vector<Diagnostic> found = validate(*app, catalog());
    (void)formatDiagnostics(found);
    (void)resolveGraph(*app);

    const std::string saved = saveApplication(*app);
    std::vector<Diagnostic> again;
    const vrflow::Result<Application> reloaded = loadApplicationString(saved, "saved.xml", &again);
    if (!reloaded.ok()) {
      std::fprintf(stderr, "saved text does not load: %s\n%s", reloaded.error().message.c_str(),
                   saved.c_str());
      std::abort();
    }
    const std::string savedAgain = saveApplication(*reloaded);
    if (savedAgain != saved) {
      std::fprintf(stderr, "save is not stable:\n%s---\n%s", saved.c_str(), savedAgain.c_str());
      std::abort();
    }
  }
  (void)checkApplicationString(xml, "fuzz.xml", catalog());

  Catalog packages;
  (void)packages.addPackageString(xml, "/fuzz/other/vrflow-package.xml");
  return 0;
}
