#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"
// Before values.hpp (sorted so): GCC's -Wshadow flags ParamKind's enumerators Vec3/Quat/Mat3 when
// the msg::Vec3/Quat/Mat3 aliases were seen first.
#include "vrflow/message/object_type.hpp"
#include "vrflow/message/values.hpp"

// Where the viewer looks from: a fixed camera, or keyframes over iterations.

namespace vrflow::viewer {

/// A perspective camera; y is up in vrflow scenes (gravity along -y).
struct Camera {
  msg::Vec3 eye{6.0, 4.0, 9.0};
  msg::Vec3 target{0.0, 0.5, 0.0};
  msg::Vec3 up{0.0, 1.0, 0.0};
  double fovYDegrees = 45.0;  ///< vertical field of view
  double nearPlane = 0.05;
  double farPlane = 500.0;
};

/// A camera at an iteration.
struct CameraKey {
  std::uint64_t iteration = 0;
  Camera camera;
};

/// Keyframes over iterations, interpolated linearly (eye, target, up, fov); before the first key
/// the first holds, after the last the last.
class CameraPath {
 public:
  /// A path with a single key: a fixed camera.
  explicit CameraPath(const Camera& fixed);
  /// Keys in strictly increasing iteration order; at least one.
  static Result<CameraPath> fromKeys(std::vector<CameraKey> keys);
  /// Parses the text format: one key per line, `iteration ex ey ez tx ty tz [fov]`, blank lines
  /// and lines starting with '#' ignored; the fov defaults to `base`'s, up and planes too.
  static Result<CameraPath> parse(const std::string& text, const Camera& base);
  /// Reads a file in the text format.
  static Result<CameraPath> load(const std::string& path, const Camera& base);

  /// The camera at `iteration`.
  Camera at(std::uint64_t iteration) const;
  const std::vector<CameraKey>& keys() const { return keys_; }

 private:
  CameraPath() = default;
  std::vector<CameraKey> keys_;
};

}  // namespace vrflow::viewer
