#include "vrflow/massspring/net.hpp"

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include "vrflow/base/file_access.hpp"
#include "vrflow/message/shape.hpp"

namespace vrflow::massspring {
namespace {

static_assert(std::endian::native == std::endian::little, "the wire layout is little-endian");

bool finite3(const double* p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

template <typename T>
void put(std::vector<std::byte>& out, T value) {
  const auto offset = out.size();
  out.resize(offset + sizeof(T));
  std::memcpy(out.data() + offset, &value, sizeof(T));
}

template <typename T>
T get(std::span<const std::byte> bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

std::string formatDouble(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

}  // namespace

Status validateNet(const Net& net) {
  const std::size_t n = net.masses.size();
  if (net.positions.size() != 3 * n || net.velocities.size() != 3 * n || net.pinned.size() != n) {
    return makeError(
        "net: " + std::to_string(n) + " masses but " + std::to_string(net.positions.size()) +
        " position, " + std::to_string(net.velocities.size()) + " velocity and " +
        std::to_string(net.pinned.size()) + " pinned values (want 3, 3 and 1 per mass)");
  }
  if (n > std::numeric_limits<std::uint32_t>::max()) return makeError("net: too many nodes");
  for (std::size_t i = 0; i < n; ++i) {
    if (!(net.masses[i] > 0) || !std::isfinite(net.masses[i])) {
      return makeError("net: node " + std::to_string(i) + " has mass " +
                       formatDouble(net.masses[i]) + " (must be finite and > 0)");
    }
    if (!finite3(&net.positions[3 * i]) || !finite3(&net.velocities[3 * i])) {
      return makeError("net: node " + std::to_string(i) + " has a non-finite position or velocity");
    }
    if (net.pinned[i] > 1)
      return makeError("net: node " + std::to_string(i) + " pinned flag must be 0 or 1");
  }
  for (std::size_t s = 0; s < net.springs.size(); ++s) {
    const auto& sp = net.springs[s];
    // The spring's name only for an error: this loop runs over every spring of every net read.
    const auto name = [s] { return "net: spring " + std::to_string(s) + " "; };
    if (sp.a >= n || sp.b >= n)
      return makeError(name() + "joins a node out of range (" + std::to_string(n) + " nodes)");
    if (sp.a == sp.b)
      return makeError(name() + "joins node " + std::to_string(sp.a) + " to itself");
    if (!(sp.restLength > 0) || !std::isfinite(sp.restLength))
      return makeError(name() + "rest length must be finite and > 0");
    if (!(sp.stiffness >= 0) || !std::isfinite(sp.stiffness))
      return makeError(name() + "stiffness must be finite and >= 0");
    if (!(sp.damping >= 0) || !std::isfinite(sp.damping))
      return makeError(name() + "damping must be finite and >= 0");
    if (!(sp.maxStretch == 0 || (sp.maxStretch >= 1 && std::isfinite(sp.maxStretch)))) {
      return makeError(name() + "maxStretch must be 0 (no limit) or >= 1");
    }
  }
  if (net.surface.size() % 3 != 0)
    return makeError("net: surface index count is not a multiple of 3");
  for (auto index : net.surface) {
    if (index >= n)
      return makeError("net: surface index " + std::to_string(index) + " out of range");
  }
  return {};
}

msg::Aabb bounds(const Net& net) {
  msg::Aabb box{};
  const std::size_t n = net.nodeCount();
  if (n == 0) return box;
  box.min = box.max = net.position(0);
  for (std::size_t i = 1; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      box.min[k] = std::min(box.min[k], net.positions[3 * i + k]);
      box.max[k] = std::max(box.max[k], net.positions[3 * i + k]);
    }
  }
  return box;
}

Result<Net> generateGrid(const GridParams& p) {
  if (p.n < 2 || p.m < 2 || p.n > 4096 || p.m > 4096) {
    return makeError("net generator: n and m must be in [2, 4096] (got " + std::to_string(p.n) +
                     " x " + std::to_string(p.m) + ")");
  }
  if (!(p.spacing > 0) || !std::isfinite(p.spacing))
    return makeError("net generator: spacing must be > 0");
  if (!(p.mass > 0) || !std::isfinite(p.mass)) return makeError("net generator: mass must be > 0");
  if (!(p.stiffness >= 0) || !std::isfinite(p.stiffness))
    return makeError("net generator: stiffness must be >= 0");
  if (!(p.shearFactor >= 0) || !(p.bendFactor >= 0))
    return makeError("net generator: shear and bend factors must be >= 0");
  if (!(p.damping >= 0) || !std::isfinite(p.damping))
    return makeError("net generator: damping must be >= 0");
  if (!(p.maxStretch == 0 || p.maxStretch >= 1))
    return makeError("net generator: max stretch must be 0 or >= 1");
  double qn = 0;
  for (double c : p.orientation) qn += c * c;
  if (!(std::abs(qn - 1) < 1e-6))
    return makeError("net generator: orientation must be a unit quaternion (x y z w)");

  Net net;
  const auto n = static_cast<std::uint32_t>(p.n);
  const auto m = static_cast<std::uint32_t>(p.m);
  const std::size_t count = std::size_t{n} * m;
  net.masses.assign(count, p.mass / static_cast<double>(count));
  net.velocities.assign(3 * count, 0.0);
  net.pinned.assign(count, 0);
  net.positions.resize(3 * count);
  const double cx = 0.5 * (p.n - 1) * p.spacing;
  const double cz = 0.5 * (p.m - 1) * p.spacing;
  for (std::uint32_t j = 0; j < m; ++j) {
    for (std::uint32_t i = 0; i < n; ++i) {
      const msg::Vec3 body{i * p.spacing - cx, 0.0, j * p.spacing - cz};
      const auto world = msg::rotate(p.orientation, body);
      const std::size_t index = std::size_t{j} * n + i;
      for (int k = 0; k < 3; ++k) net.positions[3 * index + k] = p.origin[k] + world[k];
    }
  }
  if (p.pinCorners) {
    net.pinned[0] = net.pinned[n - 1] = net.pinned[count - n] = net.pinned[count - 1] = 1;
  }
  auto id = [n](std::uint32_t i, std::uint32_t j) { return j * n + i; };
  auto add = [&](std::uint32_t a, std::uint32_t b, double rest, double k) {
    net.springs.push_back({a, b, rest, k, p.damping, p.maxStretch});
  };
  for (std::uint32_t j = 0; j < m; ++j) {
    for (std::uint32_t i = 0; i < n; ++i) {
      if (i + 1 < n) add(id(i, j), id(i + 1, j), p.spacing, p.stiffness);
      if (j + 1 < m) add(id(i, j), id(i, j + 1), p.spacing, p.stiffness);
    }
  }
  if (p.shearFactor > 0) {
    const double diag = p.spacing * std::sqrt(2.0);
    for (std::uint32_t j = 0; j + 1 < m; ++j) {
      for (std::uint32_t i = 0; i + 1 < n; ++i) {
        add(id(i, j), id(i + 1, j + 1), diag, p.shearFactor * p.stiffness);
        add(id(i + 1, j), id(i, j + 1), diag, p.shearFactor * p.stiffness);
      }
    }
  }
  if (p.bendFactor > 0) {
    for (std::uint32_t j = 0; j < m; ++j) {
      for (std::uint32_t i = 0; i < n; ++i) {
        if (i + 2 < n) add(id(i, j), id(i + 2, j), 2 * p.spacing, p.bendFactor * p.stiffness);
        if (j + 2 < m) add(id(i, j), id(i, j + 2), 2 * p.spacing, p.bendFactor * p.stiffness);
      }
    }
  }
  for (std::uint32_t j = 0; j + 1 < m; ++j) {
    for (std::uint32_t i = 0; i + 1 < n; ++i) {
      const auto a = id(i, j), b = id(i + 1, j), c = id(i, j + 1), d = id(i + 1, j + 1);
      net.surface.insert(net.surface.end(), {a, c, b, b, c, d});
    }
  }
  if (auto status = validateNet(net); !status) return status.error();
  return net;
}

Result<Net> parseNet(const std::string& text, const std::string& origin) {
  std::istringstream in(text);
  std::string line;
  int lineNumber = 0;
  auto fail = [&](const std::string& what) {
    return makeError(origin + ":" + std::to_string(lineNumber) + ": " + what);
  };
  // Reads the next line that is not empty or a comment, split into words.
  auto next = [&](std::vector<std::string>& words) {
    while (std::getline(in, line)) {
      ++lineNumber;
      if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
      std::istringstream fields(line);
      words.clear();
      for (std::string w; fields >> w;) words.push_back(w);
      if (!words.empty()) return true;
    }
    return false;
  };
  auto number = [](const std::string& word, double& out) {
    char* end = nullptr;
    out = std::strtod(word.c_str(), &end);
    return end && *end == '\0' && !word.empty();
  };
  auto count = [&](const std::string& word, std::uint64_t limit, std::uint64_t& out) {
    double v = 0;
    if (!number(word, v) || v < 0 || v != std::floor(v) || v > static_cast<double>(limit))
      return false;
    out = static_cast<std::uint64_t>(v);
    return true;
  };
  std::vector<std::string> words;
  if (!next(words) || words.size() != 2 || words[0] != "massspring" || words[1] != "1") {
    return fail("expected the header 'massspring 1'");
  }
  Net net;
  std::uint64_t nodes = 0;
  if (!next(words) || words.size() != 2 || words[0] != "nodes" ||
      !count(words[1], 1u << 24, nodes)) {
    return fail("expected 'nodes N' (N at most 16777216)");
  }
  net.masses.reserve(nodes);
  for (std::uint64_t i = 0; i < nodes; ++i) {
    if (!next(words))
      return fail("the file ends after " + std::to_string(i) + " of " + std::to_string(nodes) +
                  " nodes");
    if (words.size() != 5 && words.size() != 8)
      return fail("a node is 'x y z mass pinned [vx vy vz]'");
    double v[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t k = 0; k < words.size(); ++k) {
      if (!number(words[k], v[k])) return fail("'" + words[k] + "' is not a number");
    }
    if (v[4] != 0 && v[4] != 1) return fail("pinned must be 0 or 1");
    net.positions.insert(net.positions.end(), {v[0], v[1], v[2]});
    net.masses.push_back(v[3]);
    net.pinned.push_back(static_cast<std::uint8_t>(v[4]));
    net.velocities.insert(net.velocities.end(), {v[5], v[6], v[7]});
  }
  std::uint64_t springs = 0;
  if (!next(words) || words.size() != 2 || words[0] != "springs" ||
      !count(words[1], 1u << 26, springs)) {
    return fail("expected 'springs S' (S at most 67108864)");
  }
  for (std::uint64_t s = 0; s < springs; ++s) {
    if (!next(words))
      return fail("the file ends after " + std::to_string(s) + " of " + std::to_string(springs) +
                  " springs");
    if (words.size() != 6) return fail("a spring is 'a b restLength stiffness damping maxStretch'");
    std::uint64_t a = 0, b = 0;
    if (!count(words[0], nodes == 0 ? 0 : nodes - 1, a) ||
        !count(words[1], nodes == 0 ? 0 : nodes - 1, b)) {
      return fail("spring node indices must be integers below " + std::to_string(nodes));
    }
    double v[4];
    for (int k = 0; k < 4; ++k) {
      if (!number(words[static_cast<std::size_t>(k) + 2], v[k]))
        return fail("'" + words[static_cast<std::size_t>(k) + 2] + "' is not a number");
    }
    Spring spring{
        static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b), v[0], v[1], v[2], v[3]};
    if (spring.restLength < 0) {
      const auto pa = net.position(a), pb = net.position(b);
      spring.restLength =
          std::sqrt((pa[0] - pb[0]) * (pa[0] - pb[0]) + (pa[1] - pb[1]) * (pa[1] - pb[1]) +
                    (pa[2] - pb[2]) * (pa[2] - pb[2]));
    }
    net.springs.push_back(spring);
  }
  if (next(words)) {
    std::uint64_t triangles = 0;
    if (words.size() != 2 || words[0] != "triangles" || !count(words[1], 1u << 26, triangles)) {
      return fail("expected 'triangles T' or the end of the file");
    }
    for (std::uint64_t t = 0; t < triangles; ++t) {
      if (!next(words)) return fail("the file ends inside the triangles");
      if (words.size() != 3) return fail("a triangle is 'a b c'");
      for (const auto& w : words) {
        std::uint64_t index = 0;
        if (!count(w, nodes == 0 ? 0 : nodes - 1, index))
          return fail("triangle indices must be integers below " + std::to_string(nodes));
        net.surface.push_back(static_cast<std::uint32_t>(index));
      }
    }
    if (next(words)) return fail("unexpected text after the triangles");
  }
  if (auto status = validateNet(net); !status)
    return makeError(origin + ": " + status.error().message);
  return net;
}

Result<Net> loadNet(const std::string& path) {
  Result<std::string> text = readRegularFile(path, kMaxDataFileBytes);
  if (!text) return makeError(path + ": net file: " + text.error().message);
  return parseNet(*text, path);
}

std::string formatNet(const Net& net) {
  std::string out = "massspring 1\nnodes " + std::to_string(net.nodeCount()) + "\n";
  for (std::size_t i = 0; i < net.nodeCount(); ++i) {
    for (int k = 0; k < 3; ++k) out += formatDouble(net.positions[3 * i + k]) + " ";
    out += formatDouble(net.masses[i]) + " " + std::to_string(net.pinned[i]);
    for (int k = 0; k < 3; ++k) out += " " + formatDouble(net.velocities[3 * i + k]);
    out += "\n";
  }
  out += "springs " + std::to_string(net.springs.size()) + "\n";
  for (const auto& s : net.springs) {
    out += std::to_string(s.a) + " " + std::to_string(s.b) + " " + formatDouble(s.restLength) +
           " " + formatDouble(s.stiffness) + " " + formatDouble(s.damping) + " " +
           formatDouble(s.maxStretch) + "\n";
  }
  if (!net.surface.empty()) {
    out += "triangles " + std::to_string(net.surface.size() / 3) + "\n";
    for (std::size_t t = 0; t + 2 < net.surface.size(); t += 3) {
      out += std::to_string(net.surface[t]) + " " + std::to_string(net.surface[t + 1]) + " " +
             std::to_string(net.surface[t + 2]) + "\n";
    }
  }
  return out;
}

Status saveNet(const Net& net, const std::string& path) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) return makeError("cannot write net file '" + path + "'");
  file << formatNet(net);
  file.flush();
  if (!file) return makeError("error writing net file '" + path + "'");
  return {};
}

std::vector<std::byte> encodeSprings(std::span<const Spring> springs) {
  std::vector<std::byte> out;
  out.reserve(springs.size() * kSpringRecordSize);
  for (const auto& s : springs) {
    put(out, s.a);
    put(out, s.b);
    put(out, s.restLength);
    put(out, s.stiffness);
    put(out, s.damping);
    put(out, s.maxStretch);
  }
  return out;
}

Result<std::vector<Spring>> decodeSprings(std::span<const std::byte> bytes) {
  if (bytes.size() % kSpringRecordSize != 0) {
    return makeError("springs: " + std::to_string(bytes.size()) +
                     " bytes is not a whole number of 40-byte records");
  }
  std::vector<Spring> springs(bytes.size() / kSpringRecordSize);
  for (std::size_t i = 0; i < springs.size(); ++i) {
    const std::size_t o = i * kSpringRecordSize;
    springs[i] = {get<std::uint32_t>(bytes, o), get<std::uint32_t>(bytes, o + 4),
                  get<double>(bytes, o + 8),    get<double>(bytes, o + 16),
                  get<double>(bytes, o + 24),   get<double>(bytes, o + 32)};
  }
  return springs;
}

std::vector<std::byte> encodeIndices(std::span<const std::uint32_t> indices) {
  std::vector<std::byte> out(indices.size() * 4);
  if (!indices.empty()) std::memcpy(out.data(), indices.data(), out.size());
  return out;
}

Result<std::vector<std::uint32_t>> decodeIndices(std::span<const std::byte> bytes) {
  if (bytes.size() % 12 != 0)
    return makeError("surface: byte count is not a whole number of u32 triangles");
  std::vector<std::uint32_t> out(bytes.size() / 4);
  if (!out.empty()) std::memcpy(out.data(), bytes.data(), bytes.size());
  return out;
}

}  // namespace vrflow::massspring
