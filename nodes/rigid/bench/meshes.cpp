// vrflow-bench-rigid-meshes: the cost of moving concave meshes. The `bowls:N` scene (N bowls, each
// catching a ball and a box) stepped by the rigid solvers in one process, with the bowls as what
// they are (GImpact, today's code) and as their convex hulls (what moving meshes were before),
// measured alternately `--rounds` times on the same machine. One JSON object per line: each run,
// then the medians and the median of the rounds' ratios (hull time / GImpact time).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "vrflow/rigid/scene.hpp"
#include "vrflow/rigid/world.hpp"

namespace {

using namespace vrflow;

struct Run {
  double wallMsPerStep = 0, cpuMsPerStep = 0;
  int inside = 0;  // balls and boxes inside their bowl at the end
};

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The scene with every moving mesh replaced by the convex hull of its vertices (same mass).
Result<std::vector<rigid::Body>> asHulls(std::vector<rigid::Body> bodies) {
  for (auto& b : bodies) {
    if (b.kinematic || b.shape.kind != msg::ShapeKind::TriangleMesh) continue;
    std::vector<rigid::Vec3> points;
    for (std::size_t i = 0; i + 2 < b.shape.vertices.size(); i += 3)
      points.push_back({b.shape.vertices[i], b.shape.vertices[i + 1], b.shape.vertices[i + 2]});
    rigid::Vec3 shift{};
    auto hull = rigid::convexHullFromPoints(points, &shift);
    if (!hull) return hull.error();
    rigid::Body replaced = rigid::makeBody(b.id, hull.value(), b.mass, b.position, b.orientation);
    vrflow::msg::asEigen(replaced.position) +=
        vrflow::msg::asEigen(b.orientation) * vrflow::msg::asEigen(shift);
    b = replaced;
  }
  return bodies;
}

Result<Run> step(const std::vector<rigid::Body>& bodies, int steps) {
  rigid::RigidWorld world(
      rigid::ForceField({rigid::FieldTerm{rigid::FieldTerm::Kind::Gravity, {0, -9.81, 0}}}), {});
  if (auto ok = world.add(bodies); !ok) return ok.error();
  const auto start = std::chrono::steady_clock::now();
  const double cpu = threadCpuSeconds();
  for (int i = 0; i < steps; ++i) world.step(0.01);
  Run run;
  run.cpuMsPerStep = 1e3 * (threadCpuSeconds() - cpu) / steps;
  run.wallMsPerStep =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() /
      steps;
  // Each bowl is followed by its ball and box: inside means over its 0.5 m cavity, below its rim.
  rigid::Vec3 bowl{};
  for (const auto& b : world.state().bodies()) {
    if (b.kinematic) continue;
    if (b.shape.kind == msg::ShapeKind::TriangleMesh || b.shape.kind == msg::ShapeKind::ConvexHull)
      bowl = b.position;
    else if (std::abs(b.position[0] - bowl[0]) < 0.25 && std::abs(b.position[2] - bowl[2]) < 0.25 &&
             b.position[1] < 0.3)
      ++run.inside;
  }
  return run;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"Step time of moving concave meshes: GImpact against their convex hulls"};
  int bowls = 20, steps = 300, rounds = 5;
  bool quick = false;
  cli.add_option("--bowls", bowls, "Bowls in the scene (each with a ball and a box)")
      ->check(CLI::Range(1, 10000));
  cli.add_option("--steps", steps, "Steps of 0.01 s per run")->check(CLI::Range(1, 1000000));
  cli.add_option("--rounds", rounds, "GImpact and hull runs alternated this many times")
      ->check(CLI::Range(1, 1000));
  cli.add_flag("--quick", quick, "2 bowls, 20 steps, 1 round (checks the benchmark runs)");
  CLI11_PARSE(cli, argc, argv);
  if (quick) bowls = 2, steps = 20, rounds = 1;

  auto meshes = rigid::generateScene("bowls:" + std::to_string(bowls));
  if (!meshes) {
    std::fprintf(stderr, "vrflow-bench-rigid-meshes: %s\n", meshes.error().message.c_str());
    return 1;
  }
  auto hulls = asHulls(*meshes);
  if (!hulls) {
    std::fprintf(stderr, "vrflow-bench-rigid-meshes: %s\n", hulls.error().message.c_str());
    return 1;
  }
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  double load[1] = {0};
  getloadavg(load, 1);
  std::vector<double> gimpactMs, hullMs, ratios;
  for (int round = 0; round < rounds; ++round) {
    for (const char* variant : {"gimpact", "hull"}) {
      const bool gimpact = variant[0] == 'g';
      auto run = step(gimpact ? *meshes : *hulls, steps);
      if (!run) {
        std::fprintf(stderr, "vrflow-bench-rigid-meshes: %s: %s\n", variant,
                     run.error().message.c_str());
        return 1;
      }
      (gimpact ? gimpactMs : hullMs).push_back(run->cpuMsPerStep);
      std::printf(
          "{\"bench\":\"rigid-meshes\",\"variant\":\"%s\",\"bowls\":%d,\"steps\":%d,\"round\":%d,"
          "\"wall_ms_per_step\":%.4f,\"cpu_ms_per_step\":%.4f,\"inside_their_bowl\":%d,"
          "\"of\":%d}\n",
          variant, bowls, steps, round, run->wallMsPerStep, run->cpuMsPerStep, run->inside,
          2 * bowls);
    }
    ratios.push_back(gimpactMs.back() / hullMs.back());
  }
  getloadavg(load, 1);
  std::printf(
      "{\"bench\":\"rigid-meshes\",\"variant\":\"summary\",\"bowls\":%d,\"steps\":%d,\"rounds\":"
      "%d,\"gimpact_cpu_ms_per_step_median\":%.4f,\"hull_cpu_ms_per_step_median\":%.4f,"
      "\"gimpact_over_hull_median\":%.3f,\"machine\":\"%s\",\"load_average\":%.2f}\n",
      bowls, steps, rounds, median(gimpactMs), median(hullMs), median(ratios), host, load[0]);
  return 0;
}
