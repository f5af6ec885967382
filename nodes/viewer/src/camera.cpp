#include "vrflow/viewer/camera.hpp"

#include <cmath>
#include <sstream>

#include "vrflow/base/file_access.hpp"

namespace vrflow::viewer {
namespace {

msg::Vec3 lerp(const msg::Vec3& a, const msg::Vec3& b, double t) {
  return {a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t};
}

bool finite(const msg::Vec3& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

}  // namespace

CameraPath::CameraPath(const Camera& fixed) {
  keys_.push_back({0, fixed});
}

Result<CameraPath> CameraPath::fromKeys(std::vector<CameraKey> keys) {
  if (keys.empty()) return makeError("a camera path needs at least one key");
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const Camera& c = keys[i].camera;
    if (!finite(c.eye) || !finite(c.target) || !finite(c.up) || !std::isfinite(c.fovYDegrees)) {
      return makeError("camera key " + std::to_string(i) + ": non-finite value");
    }
    if (c.fovYDegrees <= 0.0 || c.fovYDegrees >= 180.0) {
      return makeError("camera key " + std::to_string(i) + ": fov " +
                       std::to_string(c.fovYDegrees) + " is outside (0, 180) degrees");
    }
    if (c.eye == c.target) {
      return makeError("camera key " + std::to_string(i) + ": eye and target are the same point");
    }
    if (i > 0 && keys[i].iteration <= keys[i - 1].iteration) {
      return makeError("camera key " + std::to_string(i) + ": iteration " +
                       std::to_string(keys[i].iteration) + " does not follow " +
                       std::to_string(keys[i - 1].iteration));
    }
  }
  CameraPath path;
  path.keys_ = std::move(keys);
  return path;
}

Result<CameraPath> CameraPath::parse(const std::string& text, const Camera& base) {
  std::vector<CameraKey> keys;
  std::istringstream lines(text);
  int lineNumber = 0;
  for (std::string line; std::getline(lines, line);) {
    ++lineNumber;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    CameraKey key{0, base};
    long long iteration = -1;
    fields >> iteration;
    for (double& v : key.camera.eye) fields >> v;
    for (double& v : key.camera.target) fields >> v;
    if (fields.fail() || iteration < 0) {
      return makeError("camera path line " + std::to_string(lineNumber) +
                       ": expected 'iteration ex ey ez tx ty tz [fov]', got '" + line + "'");
    }
    double fov = 0.0;
    if (fields >> fov) key.camera.fovYDegrees = fov;
    std::string extra;
    if (!fields.eof() && (fields.clear(), fields >> extra)) {
      return makeError("camera path line " + std::to_string(lineNumber) + ": unexpected '" + extra +
                       "'");
    }
    key.iteration = static_cast<std::uint64_t>(iteration);
    keys.push_back(key);
  }
  return fromKeys(std::move(keys));
}

Result<CameraPath> CameraPath::load(const std::string& path, const Camera& base) {
  Result<std::string> text = readRegularFile(path, kMaxDataFileBytes);
  if (!text) return makeError(path + ": camera path: " + text.error().message);
  auto parsed = parse(*text, base);
  if (!parsed) return makeError(path + ": " + parsed.error().message);
  return parsed;
}

Camera CameraPath::at(std::uint64_t iteration) const {
  if (iteration <= keys_.front().iteration) return keys_.front().camera;
  if (iteration >= keys_.back().iteration) return keys_.back().camera;
  std::size_t next = 1;
  while (keys_[next].iteration < iteration) ++next;
  const CameraKey& a = keys_[next - 1];
  const CameraKey& b = keys_[next];
  const double t =
      static_cast<double>(iteration - a.iteration) / static_cast<double>(b.iteration - a.iteration);
  Camera c = a.camera;
  c.eye = lerp(a.camera.eye, b.camera.eye, t);
  c.target = lerp(a.camera.target, b.camera.target, t);
  c.up = lerp(a.camera.up, b.camera.up, t);
  c.fovYDegrees = a.camera.fovYDegrees + (b.camera.fovYDegrees - a.camera.fovYDegrees) * t;
  return c;
}

}  // namespace vrflow::viewer
