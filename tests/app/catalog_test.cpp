#include "vrflow/app/catalog.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "test_support.hpp"
#include "vrflow/daemon/filter_registry.hpp"

namespace vrflow::app {
namespace {

std::string packagesDir() {
  return testing::dataDir() + "/packages";
}

std::vector<std::string> namesOf(const std::vector<PortSpec>& ports) {
  std::vector<std::string> names;
  names.reserve(ports.size());
  for (const PortSpec& port : ports) names.push_back(port.name);
  return names;
}

TEST(Catalog, ReadsEveryPackageOfAFolder) {
  const Catalog& catalog = testing::testCatalog();
  EXPECT_EQ(catalog.packages(), (std::vector<std::string>{"core", "physics"}));
  EXPECT_EQ(catalog.manifestFiles().size(), 2u);
  std::vector<std::string> palette;
  for (const ModuleType* type : catalog.moduleTypes()) {
    palette.push_back(type->package + "/" + type->type);
  }
  EXPECT_EQ(palette,
            (std::vector<std::string>{"core/relay", "core/sink", "core/source", "physics/animator",
                                      "physics/interactor", "physics/viewer"}));
}

TEST(Catalog, EveryModuleHasImplicitBeginItAndEndIt) {
  const ModuleType* sink = testing::testCatalog().findModule("core", "sink");
  ASSERT_NE(sink, nullptr);
  EXPECT_EQ(namesOf(sink->ports), (std::vector<std::string>{"in", "beginIt", "endIt"}));
  const PortSpec* beginIt = sink->findPort("beginIt");
  EXPECT_TRUE(beginIt->isInput);
  EXPECT_TRUE(beginIt->stampsOnly);
  EXPECT_FALSE(beginIt->required);
  EXPECT_EQ(beginIt->data, "any");
  const PortSpec* endIt = sink->findPort("endIt");
  EXPECT_FALSE(endIt->isInput);
  EXPECT_TRUE(endIt->stampsOnly);
}

TEST(Catalog, ReadsPortsParametersKindAndDoc) {
  const ModuleType* source = testing::testCatalog().findModule("core", "source");
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->kind, ModuleKind::Input);
  EXPECT_EQ(source->doc, "Emits numbers.");
  EXPECT_EQ(source->findPort("out")->data, "numbers");
  const ParamSpec* count = source->findParam("count");
  ASSERT_NE(count, nullptr);
  EXPECT_EQ(count->type, ParamType::Int);
  EXPECT_EQ(count->defaultValue, "0");
  EXPECT_EQ(count->min, 0.0);
  EXPECT_EQ(count->max, 10.0);
  EXPECT_EQ(count->doc, "numbers per message");
  EXPECT_EQ(source->findParam("mode")->choices, (std::vector<std::string>{"fast", "slow"}));
  EXPECT_FALSE(source->findParam("rate")->max.has_value());
  const ModuleType* interactor = testing::testCatalog().findModule("physics", "interactor");
  EXPECT_TRUE(interactor->findPort("objects")->required);
  EXPECT_EQ(interactor->kind, ModuleKind::Interactor);
  EXPECT_EQ(interactor->loc.line, 8);
}

TEST(Catalog, ExecutableNextToTheManifestBecomesAnAbsolutePath) {
  const ModuleType* source = testing::testCatalog().findModule("core", "source");
  const std::filesystem::path expected =
      std::filesystem::weakly_canonical(packagesDir() + "/core/vrflow-core-source");
  EXPECT_TRUE(std::filesystem::path(source->executable).is_absolute()) << source->executable;
  EXPECT_EQ(std::filesystem::weakly_canonical(source->executable), expected);
  EXPECT_EQ(testing::testCatalog().findModule("core", "sink")->executable, "vrflow-core-sink");
  // A relative path is taken from the manifest's folder even when nothing is there yet.
  EXPECT_EQ(testing::testCatalog().findModule("physics", "interactor")->executable,
            std::filesystem::path(packagesDir() + "/physics/bin/vrflow-physics-interactor")
                .lexically_normal()
                .string());
  EXPECT_EQ(testing::testCatalog().findModule("physics", "viewer")->executable, "/usr/bin/true");
}

TEST(Catalog, RegistersTheBuiltinFilters) {
  const Catalog catalog = daemon::makeCatalog();
  std::vector<std::string> names;
  for (const FilterType* type : catalog.filterTypes()) names.push_back(type->name);
  EXPECT_EQ(names, (std::vector<std::string>{"broadcast", "decimate", "gate", "gather", "initial",
                                             "latest", "maxfrequency", "merge", "multiplex",
                                             "passthrough", "repeat", "rotate", "route", "scatter",
                                             "stampfilter", "typefilter", "unrotate"}));
  const FilterType* merge = catalog.findFilter("merge");
  EXPECT_EQ(namesOf(merge->portsFor({})), (std::vector<std::string>{"in0", "in1", "out"}));
  EXPECT_EQ(namesOf(merge->portsFor({Param{"inputs", "3", {}}})),
            (std::vector<std::string>{"in0", "in1", "in2", "out"}));
  EXPECT_EQ(merge->portsFor({}).front().data, "any");
  const FilterType* initial = catalog.findFilter("initial");
  EXPECT_EQ(initial->initialMessagesFor({}), 1);
  EXPECT_EQ(initial->initialMessagesFor({Param{"count", "4", {}}}), 4);
  EXPECT_EQ(catalog.findFilter("broadcast")->initialMessagesFor({}), 0);
  EXPECT_EQ(namesOf(catalog.findFilter("passthrough")->portsFor({})),
            (std::vector<std::string>{"in", "out"}));
}

TEST(Catalog, StandardFiltersDeclareTheirPortsFromTheirParameters) {
  const Catalog catalog = daemon::makeCatalog();
  const auto portsOf = [&](const char* type, std::vector<Param> params) {
    return namesOf(catalog.findFilter(type)->portsFor(params));
  };
  using Names = std::vector<std::string>;
  EXPECT_EQ(portsOf("multiplex", {Param{"inputs", "3", {}}}), (Names{"in0", "in1", "in2", "out"}));
  EXPECT_EQ(portsOf("gate", {}), (Names{"in", "open", "out"}));
  EXPECT_EQ(portsOf("rotate", {Param{"outputs", "3", {}}}), (Names{"in", "out0", "out1", "out2"}));
  EXPECT_EQ(portsOf("unrotate", {}), (Names{"in0", "in1", "out"}));
  EXPECT_EQ(portsOf("scatter", {Param{"outputs", "4", {}}}),
            (Names{"in", "out0", "out1", "out2", "out3"}));
  EXPECT_EQ(portsOf("gather", {Param{"inputs", "1", {}}}), (Names{"in0", "out"}));
  EXPECT_EQ(portsOf("latest", {}), (Names{"in", "sync", "out"}));
  EXPECT_EQ(portsOf("maxfrequency", {}), (Names{"in", "out"}));
  EXPECT_EQ(portsOf("stampfilter", {}), (Names{"in", "order", "out"}));
  EXPECT_EQ(portsOf("typefilter", {}), (Names{"in", "out"}));
  EXPECT_EQ(portsOf("repeat", {}), (Names{"in", "out"}));
  EXPECT_EQ(portsOf("decimate", {}), (Names{"in", "out"}));
  EXPECT_EQ(portsOf("route", {}), (Names{"in", "interest0", "out0"}));
  EXPECT_EQ(portsOf("route", {Param{"outputs", "2", {}}}),
            (Names{"in", "interest0", "interest1", "out0", "out1"}));
  // Every input is required; every parameter has a default that is a valid value.
  for (const FilterType* type : catalog.filterTypes()) {
    for (const PortSpec& port : type->portsFor({})) {
      EXPECT_TRUE(port.required || !port.isInput) << type->name << "." << port.name;
    }
    for (const ParamSpec& param : type->params) {
      EXPECT_FALSE(checkParamValue(param, param.defaultValue).has_value())
          << type->name << "." << param.name;
    }
  }
  // latest starts its reader -> sync cycle with initial-sync triggers.
  EXPECT_EQ(catalog.findFilter("latest")->initialMessagesFor({}), 1);
  EXPECT_EQ(catalog.findFilter("latest")->initialMessagesFor({Param{"initial-sync", "0", {}}}), 0);
}

TEST(Catalog, PortsOfAnInstanceFollowItsType) {
  Filter merge;
  merge.type = "merge";
  setParam(merge.params, "inputs", "4");
  EXPECT_EQ(testing::testCatalog().portsOf(merge).size(), 5u);
  Module unknown;
  unknown.package = "core";
  unknown.type = "nothing";
  EXPECT_TRUE(testing::testCatalog().portsOf(unknown).empty());
}

TEST(Catalog, BadManifestGivesFileLineAndColumn) {
  Catalog catalog = daemon::makeCatalog();
  const Status status = catalog.addPackageString(R"(<package name="p">
  <module type="m" executable="x">
    <input name="in" date="objects"/>
    <param name="n" type="integer"/>
    <param name="k" type="int" default="12" max="10"/>
  </module>
</package>
)",
                                                 "pkg.xml");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message,
            "pkg.xml:3:22: error: unknown attribute 'date' on <input> (allowed: name, data, "
            "stamps-only, required, doc); did you mean 'data'?\n"
            "pkg.xml:4:21: error: unknown parameter type 'integer' (types: int, float, bool, "
            "string, enum, vec3, file)\n"
            "pkg.xml:5:32: error: default of parameter 'k' is 12, above its maximum 10");
  EXPECT_TRUE(catalog.packages().empty());
}

TEST(Catalog, MalformedManifestGivesFileLineAndColumn) {
  Catalog catalog = daemon::makeCatalog();
  const Status status = catalog.addPackageString("<package name=\"p\">\n  <module\n", "pkg.xml");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message, "pkg.xml:2:10: error: Error parsing start element tag");
}

TEST(Catalog, ReservedAndRepeatedPortNamesAreRejected) {
  Catalog catalog = daemon::makeCatalog();
  const Status status = catalog.addPackageString(R"(<package name="p">
  <module type="m" executable="x">
    <input name="beginIt"/>
    <input name="a"/>
    <output name="a"/>
  </module>
</package>
)",
                                                 "pkg.xml");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message,
            "pkg.xml:3:12: error: port name 'beginIt' is reserved: every module has beginIt "
            "and endIt implicitly\n"
            "pkg.xml:5:13: error: port 'a' is declared twice in 'm' (inputs and outputs share "
            "one namespace)");
}

TEST(Catalog, EnumParameterNeedsChoices) {
  Catalog catalog = daemon::makeCatalog();
  const Status status = catalog.addPackageString(
      "<package name=\"p\">\n  <module type=\"m\" executable=\"x\">\n"
      "    <param name=\"e\" type=\"enum\"/>\n  </module>\n</package>\n",
      "pkg.xml");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message.rfind("pkg.xml:3:5: error: required attribute 'choices'", 0), 0u)
      << status.error().message;
}

// mpi-ranks names the int parameter that gives a module's MPI ranks (vrflow then starts it
// through mpirun); naming anything else is an error at the attribute.
TEST(Catalog, MpiRanksNamesAnIntParameter) {
  Catalog catalog = daemon::makeCatalog();
  ASSERT_TRUE(
      catalog
          .addPackageString("<package name=\"p\">\n  <module type=\"m\" executable=\"x\" "
                            "mpi-ranks=\"blocks\">\n    <param name=\"blocks\" "
                            "type=\"int\" default=\"1\" min=\"1\"/>\n  </module>\n</package>\n",
                            "pkg.xml")
          .ok());
  const auto* type = catalog.findModule("p", "m");
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(type->mpiRanksParam, "blocks");
  for (const char* param : {"<param name=\"blocks\" type=\"float\"/>", ""}) {
    Catalog bad = daemon::makeCatalog();
    const Status status = bad.addPackageString(
        std::string("<package name=\"q\">\n  <module type=\"m\" executable=\"x\" "
                    "mpi-ranks=\"blocks\">\n    ") +
            param + "\n  </module>\n</package>\n",
        "bad.xml");
    ASSERT_FALSE(status.ok());
    EXPECT_EQ(status.error().message.rfind("bad.xml:2:", 0), 0u) << status.error().message;
    EXPECT_NE(
        status.error().message.find("mpi-ranks names 'blocks', which is not an int parameter"),
        std::string::npos)
        << status.error().message;
  }
}

// mpi-job names the string parameter whose value groups modules into one MPI job; naming
// anything else is an error at the attribute.
TEST(Catalog, MpiJobNamesAStringParameter) {
  Catalog catalog = daemon::makeCatalog();
  ASSERT_TRUE(catalog
                  .addPackageString("<package name=\"p\">\n  <module type=\"m\" executable=\"x\" "
                                    "mpi-job=\"job\">\n    <param name=\"job\" "
                                    "type=\"string\"/>\n  </module>\n</package>\n",
                                    "pkg.xml")
                  .ok());
  const auto* type = catalog.findModule("p", "m");
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(type->mpiJobParam, "job");
  EXPECT_EQ(type->mpiRanksParam, "");
  for (const char* param : {"<param name=\"job\" type=\"int\"/>", ""}) {
    Catalog bad = daemon::makeCatalog();
    const Status status = bad.addPackageString(
        std::string("<package name=\"q\">\n  <module type=\"m\" executable=\"x\" "
                    "mpi-job=\"job\">\n    ") +
            param + "\n  </module>\n</package>\n",
        "bad.xml");
    ASSERT_FALSE(status.ok());
    EXPECT_EQ(status.error().message.rfind("bad.xml:2:", 0), 0u) << status.error().message;
    EXPECT_NE(status.error().message.find("mpi-job names 'job', which is not a string parameter "
                                          "of 'm'"),
              std::string::npos)
        << status.error().message;
  }
}

TEST(Catalog, SamePackageFromAnotherFileIsAnError) {
  Catalog catalog = daemon::makeCatalog();
  ASSERT_TRUE(catalog.addPackageFile(packagesDir() + "/core/vrflow-package.xml").ok());
  EXPECT_TRUE(catalog.addPackageFile(packagesDir() + "/core/../core/vrflow-package.xml").ok());
  const Status again = catalog.addPackageString(
      "<package name=\"core\"><module type=\"x\" executable=\"y\"/></package>", "other.xml");
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.error().message, "other.xml: error: package 'core' is already loaded");
  EXPECT_EQ(catalog.moduleTypesIn("core").size(), 3u);
}

TEST(Catalog, SearchPathLetsTheFirstFolderWinAndSkipsMissingFolders) {
  Catalog catalog = daemon::makeCatalog();
  const Status status = catalog.loadSearchPath(
      {"/nonexistent/vrflow/packages", packagesDir() + "/core", packagesDir()});
  ASSERT_TRUE(status.ok()) << status.error().message;
  EXPECT_EQ(catalog.packages(), (std::vector<std::string>{"core", "physics"}));
  EXPECT_EQ(catalog.manifestFiles().size(), 2u);
}

TEST(Catalog, MissingPackageFileFailsWithItsPath) {
  Catalog catalog = daemon::makeCatalog();
  const Status status = catalog.addPackageFile("/nonexistent/vrflow-package.xml");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().message,
            "/nonexistent/vrflow-package.xml: error: cannot read file (No such file or "
            "directory)");
}

TEST(Catalog, ModuleTypesCanBeRegisteredInCode) {
  Catalog catalog = daemon::makeCatalog();
  ModuleType type;
  type.package = "code";
  type.type = "gen";
  PortSpec out;
  out.name = "out";
  out.isInput = false;
  type.ports.push_back(out);
  ASSERT_TRUE(catalog.addModuleType(type).ok());
  EXPECT_FALSE(catalog.addModuleType(type).ok());
  EXPECT_EQ(namesOf(catalog.findModule("code", "gen")->ports),
            (std::vector<std::string>{"out", "beginIt", "endIt"}));
  EXPECT_FALSE(catalog.addFilterType(*catalog.findFilter("merge")).ok());
}

TEST(ParamValue, IsCheckedAgainstItsTypeAndRange) {
  ParamSpec spec;
  spec.type = ParamType::Int;
  spec.min = -2;
  EXPECT_FALSE(checkParamValue(spec, "-2").has_value());
  EXPECT_EQ(checkParamValue(spec, "-3"), "is -3, below its minimum -2");
  EXPECT_EQ(checkParamValue(spec, "1.5"), "expects an int, got '1.5'");
  EXPECT_EQ(checkParamValue(spec, " 1"), "expects an int, got ' 1'");
  spec.type = ParamType::Float;
  EXPECT_FALSE(checkParamValue(spec, "1e3").has_value());
  EXPECT_EQ(checkParamValue(spec, "inf"), "expects a finite float, got 'inf'");
  spec.type = ParamType::Vec3;
  EXPECT_FALSE(checkParamValue(spec, "1, 2, 3").has_value());
  EXPECT_EQ(checkParamValue(spec, "1 -5 3"), "component is -5, below its minimum -2");
  EXPECT_EQ(checkParamValue(spec, "1 2 3 4"), "expects 3 numbers 'x y z', got '1 2 3 4'");
  spec.type = ParamType::Bool;
  EXPECT_FALSE(checkParamValue(spec, "false").has_value());
  EXPECT_TRUE(checkParamValue(spec, "no").has_value());
  spec.type = ParamType::String;
  EXPECT_FALSE(checkParamValue(spec, "").has_value());
}

}  // namespace
}  // namespace vrflow::app
