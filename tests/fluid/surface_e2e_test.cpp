// The fluid module's surface (`surface` = on) through `vrflow run`: on the demo scene's 2 x 2
// wall seen from above (examples/routed_wall), routed per tile against direct, and against the
// particles; `surface` off changes nothing; bad values stop the run with one clear line.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "../runtime/process_helpers.hpp"

namespace vrflow::testing {
namespace {

namespace fs = std::filesystem;

constexpr int kIterations = 16;

void replaceAll(std::string& text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
}

// routed_fluid_wall.xml or direct_fluid_wall.xml with tiles of 96 x 54 pixels (no
// supersampling, PNG frames into `frames`) and, with `surface`, the water's surface instead of
// its particles; with `liquid` false, neither (particles-every 0: the liquid's bytes are the
// difference).
std::string wallApplication(const std::string& name, const std::string& frames, bool surface,
                            bool liquid = true) {
  std::string app = readFile(sourceDir() + "/examples/routed_wall/" + name);
  replaceAll(app, "\"../paper_scene/scene.json\"",
             "\"" + sourceDir() + "/examples/paper_scene/scene.json\"");
  replaceAll(app, "<param name=\"width\" value=\"480\"/>", "<param name=\"width\" value=\"96\"/>");
  replaceAll(app, "<param name=\"height\" value=\"270\"/>",
             "<param name=\"height\" value=\"54\"/>");
  for (const char* dir : {"routed-fluid-wall", "direct-fluid-wall"}) {
    replaceAll(app, "<param name=\"output-dir\" value=\"" + std::string(dir) + "\"/>",
               "<param name=\"output-dir\" value=\"" + frames +
                   "\"/><param name=\"format\" value=\"png\"/><param name=\"supersample\" "
                   "value=\"1\"/>");
  }
  if (surface) {
    replaceAll(app, "<param name=\"particle-regions\" value=\"4 1 4\"/>",
               "<param name=\"particle-regions\" value=\"4 1 4\"/><param name=\"surface\" "
               "value=\"on\"/>");
  }
  if (!liquid) {
    replaceAll(app, "<param name=\"particles-every\" value=\"1\"/>",
               "<param name=\"particles-every\" value=\"0\"/>");
  }
  return app;
}

// Runs `app` in dir/name; its report.
nlohmann::json runIn(const TempDir& dir, const std::string& name, const std::string& app) {
  const auto folder = dir.file(name);
  fs::create_directories(folder);
  const auto file = dir.write(name + ".xml", app);
  const auto result =
      runCommand({"/bin/sh", "-c",
                  "cd '" + folder + "' && exec '" + binDir() + "/vrflow' run '" + file + "' -n " +
                      std::to_string(kIterations) + " --no-progress --report report.json"},
                 300);
  EXPECT_EQ(result.exitCode, 0) << result.err;
  return nlohmann::json::parse(readFile(folder + "/report.json"));
}

// Bytes delivered to each tile's objects input, by tile id.
std::map<std::string, double> bytesToTiles(const nlohmann::json& report) {
  std::map<std::string, double> bytes;
  for (const auto& c : report["connections"]) {
    const auto to = c["to"].get<std::string>();
    if (to.rfind("tile", 0) == 0 && to.ends_with(".objects")) {
      bytes[to.substr(0, to.find('.'))] += c["bytes"].get<double>();
    }
  }
  return bytes;
}

std::string digestOf(const nlohmann::json& report, const std::string& module,
                     const std::string& port) {
  for (const auto& output : report["outputs"]) {
    if (output["module"] == module && output["port"] == port) return output["last_digest"].dump();
  }
  return "";
}

// The surface as 4 x 1 x 4 regions, routed to the tile that sees each: every routed frame is
// the direct one, byte for byte (a tile is sent every region it shows); each tile gets at
// least 10x fewer bytes of the liquid than with the particles routed the same way (a tile's
// bytes less those of the same run without the liquid's payload: the bodies and the net;
// measured 14.9x over these 16 iterations; 9.3x while a region kept whole the triangles that
// cross its box, whose bounds then met the neighbouring tiles' volumes: nodes/fluid/README.md);
// the liquid's forces are the same bits.
TEST(FluidSurfaceModule, RoutedSurfaceFramesEqualDirectOnesWithFarFewerBytesThanParticles) {
  TempDir dir;
  const auto routed =
      runIn(dir, "routed", wallApplication("routed_fluid_wall.xml", dir.file("routed/f"), true));
  const auto direct =
      runIn(dir, "direct", wallApplication("direct_fluid_wall.xml", dir.file("direct/f"), true));
  const auto particles = runIn(
      dir, "particles", wallApplication("routed_fluid_wall.xml", dir.file("particles/f"), false));
  const auto dry =
      runIn(dir, "dry", wallApplication("routed_fluid_wall.xml", dir.file("dry/f"), false, false));
  ASSERT_EQ(dry["status"], "ok");
  ASSERT_EQ(routed["status"], "ok");
  ASSERT_EQ(direct["status"], "ok");
  ASSERT_EQ(particles["status"], "ok");
  int identical = 0, differentFromParticles = 0;
  for (int k = 0; k < 4; ++k) {
    for (int i = 0; i < kIterations; ++i) {
      char name[64];
      std::snprintf(name, sizeof name, "/f/tile%d_%06d.png", k, i);
      const auto frame = readFile(dir.file("routed") + name);
      EXPECT_FALSE(frame.empty()) << name;
      if (!frame.empty() && frame == readFile(dir.file("direct") + name)) ++identical;
      if (frame != readFile(dir.file("particles") + name)) ++differentFromParticles;
    }
  }
  EXPECT_EQ(identical, 4 * kIterations) << "routed surface frames differ from direct ones";
  EXPECT_GT(differentFromParticles, 0) << "the surface is drawn, not the particles";
  const auto surfaceBytes = bytesToTiles(routed);
  const auto particleBytes = bytesToTiles(particles);
  const auto dryBytes = bytesToTiles(dry);
  ASSERT_EQ(surfaceBytes.size(), 4u);
  for (const auto& [tile, bytes] : surfaceBytes) {
    const double surface = bytes - dryBytes.at(tile);
    const double points = particleBytes.at(tile) - dryBytes.at(tile);
    std::printf(
        "%s: the liquid's bytes per iteration: surface %.0f, particles %.0f (%.1fx less); "
        "the tile's: %.0f against %.0f (%.1fx less)\n",
        tile.c_str(), surface / kIterations, points / kIterations, points / surface,
        bytes / kIterations, particleBytes.at(tile) / kIterations, particleBytes.at(tile) / bytes);
    EXPECT_GT(surface, 0.0) << tile;
    EXPECT_GT(points, 10.0 * surface) << tile;
  }
  // The surface changes what the fluid sends, not what it computes.
  EXPECT_EQ(digestOf(routed, "water", "forces"), digestOf(particles, "water", "forces"));
  EXPECT_NE(digestOf(routed, "water", "fluid"), digestOf(particles, "water", "fluid"));
  EXPECT_EQ(digestOf(routed, "water", "fluid"), digestOf(direct, "water", "fluid"));
  EXPECT_TRUE(leftoverProcesses().empty());
}

// The example packages (routing/tile-viewer, which records what it receives).
std::string examplePackages() {
  return binDir() + "/../share/vrflow/example-packages";
}

std::string aloneApplication(const std::string& extra) {
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="fluid-surface" version="1">
  <hosts>
    <host id="local" address="127.0.0.1"/>
  </hosts>
  <modules>
    <module id="water" package="fluid" type="fluid" host="local">
      <param name="nx" value="16"/>
      <param name="ny" value="20"/>
      <param name="nz" value="16"/>
      <param name="cell-size" value="0.05"/>
      <param name="fill-max" value="0.4 0.5 0.8"/>
)" + extra +
         R"(    </module>
    <module id="v" package="routing" type="tile-viewer" host="local">
      <param name="box" value="all"/>
    </module>
  </modules>
  <connections>
    <connection from="water.fluid" to="v.objects"/>
  </connections>
</application>
)";
}

// `surface` off, said or not, sends the same bits as before the parameter existed (the report's
// digest of the fluid output is equal); on, it differs. (That the forces stay the same bits with
// the surface on is checked on the wall above.)
TEST(FluidSurfaceModule, SurfaceOffChangesNoDigestAndOnChangesOnlyTheFluidOutput) {
  TempDir dir;
  std::map<std::string, nlohmann::json> reports;
  for (const std::string mode : {"", "off", "on"}) {
    const std::string name = mode.empty() ? "default" : mode;
    const auto app = dir.write(
        name + ".xml",
        aloneApplication(
            mode.empty() ? "" : "      <param name=\"surface\" value=\"" + mode + "\"/>\n"));
    const auto result = runVrflow({"--packages", examplePackages(), "run", app, "--iterations",
                                   "20", "--no-progress", "--report", dir.file(name + ".json")},
                                  120);
    ASSERT_EQ(result.exitCode, 0) << result.err;
    reports[name] = nlohmann::json::parse(readFile(dir.file(name + ".json")));
  }
  EXPECT_FALSE(digestOf(reports["default"], "water", "fluid").empty());
  EXPECT_EQ(digestOf(reports["default"], "water", "fluid"),
            digestOf(reports["off"], "water", "fluid"));
  EXPECT_NE(digestOf(reports["on"], "water", "fluid"), digestOf(reports["off"], "water", "fluid"));
  EXPECT_TRUE(leftoverProcesses().empty());
}

struct BadValue {
  std::string params;
  std::string command;  // "run" or "validate"
  std::string expected;
};

TEST(FluidSurfaceModule, BadSurfaceValuesStopWithOneLineNamingTheParameter) {
  const BadValue cases[] = {
      {"<param name=\"surface\" value=\"maybe\"/>", "validate", "surface"},
      {"<param name=\"surface-resolution\" value=\"0\"/>", "validate", "surface-resolution"},
      {"<param name=\"surface\" value=\"on\"/><param name=\"job\" value=\"j\"/>", "run",
       "surface = on with job"},
  };
  for (const auto& bad : cases) {
    TempDir dir;
    const auto app = dir.write("bad.xml", aloneApplication("      " + bad.params + "\n"));
    const auto result = bad.command == "run"
                            ? runVrflow({"--packages", examplePackages(), "run", app,
                                         "--iterations", "3", "--no-progress"},
                                        120)
                            : runVrflow({"--packages", examplePackages(), "validate", app}, 60);
    EXPECT_NE(result.exitCode, 0) << bad.params;
    EXPECT_NE((result.out + result.err).find(bad.expected), std::string::npos)
        << bad.params << "\n"
        << result.out << result.err;
    EXPECT_TRUE(leftoverProcesses().empty());
  }
}

}  // namespace
}  // namespace vrflow::testing
