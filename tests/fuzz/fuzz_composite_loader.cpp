// libFuzzer target for the composite loader: load any text as a composite file (NAME.vrc.xml),
// save it and check that saving is stable (load(save(x)) saves to the same bytes), then expand
// one instance of it (parameters at their defaults, or "1" where a parameter has none) into a
// flat application and validate that against a small catalog. Must never crash or hang.
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

// An application with one host and one instance `c` of `composite`, every parameter without a
// default set to "1" (the smallest count a <repeat> over it can use).
vrflow::app::Application oneInstanceOf(const vrflow::app::Composite& composite) {
  using namespace vrflow::app;
  Application app;
  app.name = "fuzz";
  app.hosts.push_back(Host{"localhost", "127.0.0.1", {}});
  Instance instance;
  instance.id = "c";
  instance.composite = composite.name;
  instance.host = "localhost";
  for (const CompositeParam& param : composite.params) {
    if (!param.defaultValue) instance.params.push_back(Param{param.name, "1", {}});
  }
  app.instances.push_back(std::move(instance));
  return app;
}

}  // namespace

// NOLINTNEXTLINE(readability-identifier-naming): the name libFuzzer calls
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace vrflow::app;
  const std::string_view xml(reinterpret_cast<const char*>(data), size);

  std::vector<Diagnostic> problems;
  const vrflow::Result<Composite> composite = loadCompositeString(xml, "fuzz.vrc.xml", &problems);
  (void)formatDiagnostics(problems);
  if (!composite.ok()) return 0;

  const std::string saved = saveComposite(*composite);
  std::vector<Diagnostic> again;
  const vrflow::Result<Composite> reloaded = loadCompositeString(saved, "saved.vrc.xml", &again);
  if (!reloaded.ok()) {
    std::fprintf(stderr, "saved text does not load: %s\n%s", reloaded.error().message.c_str(),
                 saved.c_str());
    std::abort();
  }
  const std::string savedAgain = saveComposite(*reloaded);
  if (savedAgain != saved) {
    std::fprintf(stderr, "save is not stable:\n%s---\n%s", saved.c_str(), savedAgain.c_str());
    std::abort();
  }

  if (composite->name.empty()) return 0;
  CompositeSources sources;
  sources.composites.push_back(*composite);
  std::vector<Diagnostic> expansion;
  const vrflow::Result<Application> flat =
      expandComposites(oneInstanceOf(*composite), sources, &expansion);
  (void)formatDiagnostics(expansion);
  if (flat.ok()) {
    (void)formatDiagnostics(validate(*flat, catalog()));
    (void)saveApplication(*flat);
  }
  return 0;
}
