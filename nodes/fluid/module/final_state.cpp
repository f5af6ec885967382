#include "final_state.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "vrflow/message/shape.hpp"

namespace vrflow::fluid {
namespace {

void vec(std::FILE* file, const char* key, const double* v, int n) {
  std::fprintf(file, ", \"%s\": [", key);
  for (int i = 0; i < n; ++i) std::fprintf(file, "%s%.9g", i ? ", " : "", v[i]);
  std::fprintf(file, "]");
}

}  // namespace

double surfaceLevel(const FluidSettings& s, const std::vector<float>& particles) {
  const double lowest = -std::numeric_limits<double>::infinity();
  std::vector<double> top(static_cast<std::size_t>(s.nx) * static_cast<std::size_t>(s.nz), lowest);
  for (std::size_t p = 0; p + 2 < particles.size(); p += 3) {
    const int i = static_cast<int>(std::floor((particles[p] - s.origin[0]) / s.cellSize));
    const int k = static_cast<int>(std::floor((particles[p + 2] - s.origin[2]) / s.cellSize));
    if (i < 0 || i >= s.nx || k < 0 || k >= s.nz) continue;
    auto& t = top[static_cast<std::size_t>(k) * static_cast<std::size_t>(s.nx) +
                  static_cast<std::size_t>(i)];
    t = std::max(t, static_cast<double>(particles[p + 1]));
  }
  std::vector<double> filled;
  for (const double t : top) {
    if (t > lowest) filled.push_back(t);
  }
  if (filled.empty()) return s.origin[1];
  const auto middle = filled.begin() + static_cast<std::ptrdiff_t>(filled.size() / 2);
  std::nth_element(filled.begin(), middle, filled.end());
  return *middle;
}

Status writeFinalState(const std::string& path, const FinalState& st) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file) return makeError("fluid: cannot write the state file " + path);
  const std::size_t count = st.particles.size() / 3;
  double centroid[3] = {0, 0, 0};
  double low[3] = {0, 0, 0}, high[3] = {0, 0, 0};
  for (std::size_t p = 0; p < count; ++p) {
    for (int c = 0; c < 3; ++c) {
      const double x = st.particles[3 * p + static_cast<std::size_t>(c)];
      centroid[c] += x;
      low[c] = p == 0 ? x : std::min(low[c], x);
      high[c] = p == 0 ? x : std::max(high[c], x);
    }
  }
  for (double& c : centroid) c = count > 0 ? c / static_cast<double>(count) : 0.0;
  const double level = surfaceLevel(st.settings, st.particles);
  std::fprintf(file, "{\"time\": %.9g, \"steps\": %llu, \"particles\": %zu", st.time, st.steps,
               count);
  std::fprintf(file, ", \"initialVolume\": %.9g, \"volume\": %.9g, \"maxSpeed\": %.9g",
               st.initialVolume, st.volume, st.maxSpeed);
  std::fprintf(file, ", \"level\": %.9g", level);
  vec(file, "centroid", centroid, 3);
  vec(file, "particlesMin", low, 3);
  vec(file, "particlesMax", high, 3);
  std::fprintf(file, ", \"bodies\": [");
  for (std::size_t b = 0; b < st.bodies.size(); ++b) {
    const auto& body = st.bodies[b];
    const auto bounds = msg::worldBounds(body.shape, body.position, body.orientation);
    const double height = bounds.max[1] - bounds.min[1];
    const double submerged =
        height > 0.0 ? std::clamp((level - bounds.min[1]) / height, 0.0, 1.0) : 0.0;
    std::fprintf(file, "%s\n  {\"id\": %llu, \"kinematic\": %s", b ? "," : "",
                 static_cast<unsigned long long>(body.id), body.kinematic ? "true" : "false");
    vec(file, "position", body.position.data(), 3);
    vec(file, "boundsMin", bounds.min.data(), 3);
    vec(file, "boundsMax", bounds.max.data(), 3);
    std::fprintf(file, ", \"submerged\": %.9g", submerged);
    if (b < st.forces.size()) {
      const auto& f = st.forces[b];
      std::fprintf(file, ", \"faces\": %d", f.cells);
      vec(file, "force", f.force.data(), 3);
      vec(file, "torque", f.torque.data(), 3);
    }
    std::fprintf(file, "}");
  }
  std::fprintf(file, "%s]}\n", st.bodies.empty() ? "" : "\n");
  const bool ok = std::fclose(file) == 0;
  if (!ok) return makeError("fluid: cannot write the state file " + path);
  return {};
}

}  // namespace vrflow::fluid
