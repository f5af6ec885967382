#include "vrflow/camera/synthetic_user.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>

namespace vrflow::camera {

namespace {

enum Joint {
  kHead,
  kNeck,
  kPelvis,
  kShoulderL,
  kElbowL,
  kWristL,
  kHandL,
  kShoulderR,
  kElbowR,
  kWristR,
  kHandR
};

// Bones: joint pairs and radii (m). The head is a sphere (a capsule of zero length).
struct Bone {
  Joint from, to;
  double radius;
};
constexpr Bone kBones[] = {
    {kHead, kHead, 0.11},     {kNeck, kPelvis, 0.16},   {kShoulderL, kElbowL, 0.05},
    {kElbowL, kWristL, 0.04}, {kWristL, kHandL, 0.045}, {kShoulderR, kElbowR, 0.05},
    {kElbowR, kWristR, 0.04}, {kWristR, kHandR, 0.045},
};

}  // namespace

double Capsule::signedDistance(const cv::Vec3d& p) const {
  const cv::Vec3d e = b - a;
  const double length2 = e.dot(e);
  const double u = length2 > 0 ? std::clamp((p - a).dot(e) / length2, 0.0, 1.0) : 0.0;
  return cv::norm(p - (a + u * e)) - radius;
}

SyntheticUser::SyntheticUser(const UserPose& pose) {
  for (const Bone& bone : kBones)
    capsules_.push_back({pose[bone.from], pose[bone.to], bone.radius});
}

double SyntheticUser::signedDistance(const cv::Vec3d& p) const {
  double d = std::numeric_limits<double>::infinity();
  for (const Capsule& capsule : capsules_) d = std::min(d, capsule.signedDistance(p));
  return d;
}

VoxelGrid SyntheticUser::voxelize(const GridSpec& spec) const {
  VoxelGrid grid(spec);
  for (int k = 0; k < spec.nz; ++k)
    for (int j = 0; j < spec.ny; ++j)
      for (int i = 0; i < spec.nx; ++i)
        grid.occupied[spec.index(i, j, k)] = signedDistance(spec.centre(i, j, k)) <= 0 ? 1 : 0;
  return grid;
}

cv::Mat SyntheticUser::renderMask(const CameraCalibration& camera) const {
  const cv::Size size = camera.imageSize;
  std::vector<cv::Point2f> pixels;
  pixels.reserve(static_cast<std::size_t>(size.area()));
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u)
      pixels.emplace_back(static_cast<float>(u), static_cast<float>(v));
  std::vector<cv::Point2f> rays;
  cv::undistortPoints(pixels, rays, camera.cameraMatrix, camera.distortion);
  // Capsules in the camera frame; a pixel is inside when its ray passes within a capsule's
  // radius of its segment: min over u in [0,1] of |P(u)|^2 - (P(u).d)^2, a quadratic in u.
  std::vector<Capsule> local;
  for (const Capsule& c : capsules_)
    local.push_back({camera.rotation * c.a + camera.translation,
                     camera.rotation * c.b + camera.translation, c.radius});
  cv::Mat mask(size, CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < size.height; ++v) {
    auto* row = mask.ptr<std::uint8_t>(v);
    for (int u = 0; u < size.width; ++u) {
      const cv::Point2f& ray = rays[static_cast<std::size_t>(v) * size.width + u];
      const cv::Vec3d d = cv::normalize(cv::Vec3d(ray.x, ray.y, 1.0));
      for (const Capsule& c : local) {
        const cv::Vec3d e = c.b - c.a;
        const double ad = c.a.dot(d), ed = e.dot(d);
        const double qa = e.dot(e) - ed * ed, qb = 2 * (c.a.dot(e) - ad * ed);
        const double qc = c.a.dot(c.a) - ad * ad;
        const double at = qa > 1e-15 ? std::clamp(-qb / (2 * qa), 0.0, 1.0) : (qb < 0 ? 1.0 : 0.0);
        if (qa * at * at + qb * at + qc <= c.radius * c.radius && ad + at * ed > 0) {
          row[u] = 255;
          break;
        }
      }
    }
  }
  return mask;
}

UserPose standingPose() {
  return {cv::Vec3d{0, 1.62, 0}, {0, 1.45, 0},       {0, 0.95, 0},       {0.2, 1.42, 0},
          {0.45, 1.38, 0.05},    {0.62, 1.3, 0.2},   {0.66, 1.28, 0.3},  {-0.2, 1.42, 0},
          {-0.3, 1.45, 0.25},    {-0.32, 1.5, 0.48}, {-0.33, 1.52, 0.58}};
}

}  // namespace vrflow::camera
