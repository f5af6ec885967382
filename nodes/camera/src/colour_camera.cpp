#include "vrflow/camera/colour_camera.hpp"

#include <GL/gl.h>
#include <GL/osmesa.h>

#include <array>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "vrflow/camera/synthetic_scene.hpp"
#include "vrflow/message/shape.hpp"
#include "vrflow/viewer/renderer.hpp"

namespace vrflow::camera {

namespace {

constexpr double kNear = 0.05, kFar = 100.0;

// Base colours (linear RGB) of the body's capsules, in SyntheticUser's order: head, torso, then
// upper and lower arms and hands, left then right. Skin for the head and hands, cloth elsewhere.
constexpr std::array<float, 3> kSkin{0.86f, 0.66f, 0.52f};
constexpr std::array<float, 3> kShirt{0.20f, 0.32f, 0.70f};
constexpr std::array<float, 3> kSleeve{0.62f, 0.18f, 0.16f};

std::array<float, 3> capsuleColour(std::size_t index, std::size_t count) {
  if (index == 0) return kSkin;
  if (index == 1) return kShirt;
  const std::size_t perArm = (count - 2) / 2;
  return ((index - 2) % perArm == perArm - 1) ? kSkin : kSleeve;
}

// The viewer's lighting (vrflow/viewer/renderer.hpp) of a surface with unit normal n.
float lit(const cv::Vec3d& n) {
  const auto& l = viewer::kLighting;
  const cv::Vec3d key =
      cv::normalize(cv::Vec3d(l.keyDirection[0], l.keyDirection[1], l.keyDirection[2]));
  const cv::Vec3d fill =
      cv::normalize(cv::Vec3d(l.fillDirection[0], l.fillDirection[1], l.fillDirection[2]));
  return l.ambient + l.key * static_cast<float>(std::max(0.0, n.dot(key))) +
         l.fill * static_cast<float>(std::max(0.0, n.dot(fill)));
}

// A rotation taking the y axis onto the unit vector `d`.
cv::Matx33d yAxisTo(const cv::Vec3d& d) {
  const cv::Vec3d y(0, 1, 0);
  const cv::Vec3d axis = y.cross(d);
  const double s = cv::norm(axis), c = y.dot(d);
  if (s < 1e-12) return c > 0 ? cv::Matx33d::eye() : cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1);
  cv::Matx33d rotation;
  cv::Rodrigues(axis * (std::atan2(s, c) / s), rotation);
  return rotation;
}

}  // namespace

struct ColourCamera::Impl {
  CameraCalibration calibration;
  ColourCameraSettings settings;
  OSMesaContext context = nullptr;
  std::vector<std::uint8_t> rgba;  // rows from the bottom
  cv::Mat room;                    // the empty room, BGR, no noise
  cv::Mat distortX, distortY;      // pinhole render -> distorted image (empty: no distortion)
  ~Impl() {
    if (context) OSMesaDestroyContext(context);
  }

  void drawCapsule(const Capsule& capsule, const std::array<float, 3>& base) const;
};

void ColourCamera::Impl::drawCapsule(const Capsule& capsule,
                                     const std::array<float, 3>& base) const {
  const cv::Vec3d axis = capsule.b - capsule.a;
  const double length = cv::norm(axis);
  const double halfHeight = length / 2;
  const cv::Matx33d rotation = length > 0 ? yAxisTo(axis / length) : cv::Matx33d::eye();
  const cv::Vec3d centre = (capsule.a + capsule.b) * 0.5;
  const auto mesh =
      msg::renderMesh(msg::Shape::capsule(capsule.radius, halfHeight), settings.segments);
  glBegin(GL_TRIANGLES);
  for (const auto index : mesh.indices) {
    const cv::Vec3d local(mesh.xyz[3 * index], mesh.xyz[3 * index + 1], mesh.xyz[3 * index + 2]);
    const cv::Vec3d onAxis(0, std::clamp(local[1], -halfHeight, halfHeight), 0);
    const cv::Vec3d normal = rotation * cv::normalize(local - onAxis);
    const cv::Vec3d world = centre + rotation * local;
    // Horizontal stripes of 2.5 cm: texture inside the silhouette.
    const float stripe = std::fmod(std::abs(world[1]) * 20.0, 1.0) < 0.5 ? 1.0f : 0.8f;
    const float light = lit(normal) * stripe;
    glColor3f(base[0] * light, base[1] * light, base[2] * light);
    glVertex3d(world[0], world[1], world[2]);
  }
  glEnd();
}

ColourCamera::ColourCamera(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ColourCamera::ColourCamera(ColourCamera&&) noexcept = default;
ColourCamera& ColourCamera::operator=(ColourCamera&&) noexcept = default;
ColourCamera::~ColourCamera() = default;

Result<ColourCamera> ColourCamera::create(const CameraCalibration& calibration,
                                          const ColourCameraSettings& settings) {
  const cv::Size size = calibration.imageSize;
  if (size.width < 1 || size.height < 1 || size.width > 8192 || size.height > 8192)
    return Error{"synthetic camera: image size " + std::to_string(size.width) + "x" +
                 std::to_string(size.height) + " is not within 1..8192"};
  if (settings.segments < 4) return Error{"synthetic camera: segments must be at least 4"};
  auto impl = std::make_unique<Impl>();
  impl->calibration = calibration;
  impl->settings = settings;
  impl->context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
  if (!impl->context)
    return Error{"synthetic camera: OSMesa could not create an RGBA context with 24-bit depth"};
  impl->rgba.resize(static_cast<std::size_t>(size.width) * size.height * 4);
  impl->room = renderBackground(size, settings.roomSeed, 0, 0);
  if (cv::countNonZero(calibration.distortion) > 0) {
    // Where each pixel of the distorted image lies in the pinhole render.
    std::vector<cv::Point2f> pixels;
    pixels.reserve(static_cast<std::size_t>(size.area()));
    for (int v = 0; v < size.height; ++v)
      for (int u = 0; u < size.width; ++u)
        pixels.emplace_back(static_cast<float>(u), static_cast<float>(v));
    std::vector<cv::Point2f> pinhole;
    cv::undistortPoints(pixels, pinhole, calibration.cameraMatrix, calibration.distortion,
                        cv::noArray(), calibration.cameraMatrix);
    impl->distortX.create(size, CV_32FC1);
    impl->distortY.create(size, CV_32FC1);
    for (int v = 0; v < size.height; ++v)
      for (int u = 0; u < size.width; ++u) {
        const auto& p = pinhole[static_cast<std::size_t>(v) * size.width + u];
        impl->distortX.at<float>(v, u) = p.x;
        impl->distortY.at<float>(v, u) = p.y;
      }
  }
  return ColourCamera(std::move(impl));
}

Result<cv::Mat> ColourCamera::render(const SyntheticUser* user, std::uint64_t frame) {
  Impl& r = *impl_;
  const CameraCalibration& c = r.calibration;
  const cv::Size size = c.imageSize;
  cv::Mat image = r.room.clone();
  if (user) {
    if (!OSMesaMakeCurrent(r.context, r.rgba.data(), GL_UNSIGNED_BYTE, size.width, size.height))
      return Error{"synthetic camera: OSMesa could not bind the frame buffer"};
    glViewport(0, 0, size.width, size.height);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_LIGHTING);
    glShadeModel(GL_SMOOTH);
    // OpenCV's pixel (u, v) has its centre at u, v and covers [u - 1/2, u + 1/2]; OpenGL's
    // window pixel i covers [i, i + 1]. The frustum's edges are the image's pixel edges.
    const double fx = c.cameraMatrix(0, 0), fy = c.cameraMatrix(1, 1);
    const double cx = c.cameraMatrix(0, 2), cy = c.cameraMatrix(1, 2);
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glFrustum((-0.5 - cx) * kNear / fx, (size.width - 0.5 - cx) * kNear / fx,
              -(size.height - 0.5 - cy) * kNear / fy, (cy + 0.5) * kNear / fy, kNear, kFar);
    // OpenCV's camera looks along +z with y down; OpenGL's eye along -z with y up.
    GLdouble view[16] = {};
    for (int row = 0; row < 3; ++row) {
      const double flip = row == 0 ? 1.0 : -1.0;
      for (int col = 0; col < 3; ++col) view[col * 4 + row] = flip * c.rotation(row, col);
      view[12 + row] = flip * c.translation[row];
    }
    view[15] = 1;
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixd(view);
    const auto& capsules = user->capsules();
    for (std::size_t n = 0; n < capsules.size(); ++n)
      r.drawCapsule(capsules[n], capsuleColour(n, capsules.size()));
    glFinish();
    cv::Mat rendered(size, CV_8UC4, r.rgba.data());
    cv::Mat drawn;
    cv::flip(rendered, drawn, 0);  // OpenGL's rows start at the bottom
    if (!r.distortX.empty()) {
      cv::Mat distorted;
      cv::remap(drawn, distorted, r.distortX, r.distortY, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
      drawn = distorted;
    }
    cv::Mat bgr, alpha;
    cv::cvtColor(drawn, bgr, cv::COLOR_RGBA2BGR);
    cv::extractChannel(drawn, alpha, 3);
    bgr.copyTo(image, alpha > 127);
  }
  addSensorNoise(image, r.settings.noise,
                 static_cast<std::uint64_t>(r.settings.roomSeed) * 1000003u + frame + 1);
  return image;
}

}  // namespace vrflow::camera
