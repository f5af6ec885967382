// The user animator's library: the surface velocity estimated from consecutive distance fields
// against the known motion of a translating sphere and a turning synthetic user, and the user
// object's round trip through a message (user_object.hpp, user_copy.hpp, user_surface.hpp).
#include "vrflow/camera/user_velocity.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "vrflow/camera/distance_field.hpp"
#include "vrflow/camera/synthetic_user.hpp"
#include "vrflow/camera/user_copy.hpp"
#include "vrflow/camera/user_object.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/byte_sink.hpp"

namespace vrflow::camera {
namespace {

// A solid given by its analytic signed distance.
template <typename Distance>
VoxelGrid voxelize(const GridSpec& spec, Distance distance) {
  VoxelGrid grid(spec);
  for (int k = 0; k < spec.nz; ++k)
    for (int j = 0; j < spec.ny; ++j)
      for (int i = 0; i < spec.nx; ++i)
        grid.occupied[spec.index(i, j, k)] = distance(spec.centre(i, j, k)) <= 0 ? 1 : 0;
  return grid;
}

// Normal speeds, estimated and true, over the cells within one voxel of the surface.
struct SpeedError {
  double meanAbs = 0;   ///< mean |estimated - true| normal speed (m/s)
  double meanTrue = 0;  ///< mean |true normal speed|, for scale
  int cells = 0;
};

template <typename Distance, typename Velocity>
SpeedError normalSpeedError(const GridSpec& spec, const std::vector<float>& sdf,
                            const std::vector<float>& velocity, Distance distance,
                            Velocity trueVelocity) {
  SpeedError e;
  const double h = 1e-4;
  for (int k = 0; k < spec.nz; ++k)
    for (int j = 0; j < spec.ny; ++j)
      for (int i = 0; i < spec.nx; ++i) {
        const std::size_t c = spec.index(i, j, k);
        if (std::abs(sdf[c]) > spec.voxelSize) continue;
        const cv::Vec3d x = spec.centre(i, j, k);
        cv::Vec3d n;
        for (int a = 0; a < 3; ++a) {
          cv::Vec3d d(0, 0, 0);
          d[a] = h;
          n[a] = (distance(x + d) - distance(x - d)) / (2 * h);
        }
        if (cv::norm(n) < 0.5) continue;
        n /= cv::norm(n);
        const cv::Vec3d estimated(velocity[3 * c], velocity[3 * c + 1], velocity[3 * c + 2]);
        const double truth = trueVelocity(x).dot(n);
        e.meanAbs += std::abs(estimated.dot(n) - truth);
        e.meanTrue += std::abs(truth);
        ++e.cells;
      }
  if (e.cells > 0) {
    e.meanAbs /= e.cells;
    e.meanTrue /= e.cells;
  }
  return e;
}

TEST(SurfaceVelocity, TranslatingSphereGivesItsNormalSpeed) {
  const GridSpec spec = GridSpec::cube({-0.7, -0.7, -0.7}, 1.4, 64);  // 2.2 cm voxels
  const double dt = 0.04;
  const cv::Vec3d v(0.5, -0.2, 0.3), c0(0.01, 0.02, -0.03), c1 = c0 + v * dt;  // 2.4 cm a frame
  auto sphereAt = [](cv::Vec3d c) {
    return [c](const cv::Vec3d& x) { return cv::norm(x - c) - 0.3; };
  };
  const auto before = signedDistanceField(voxelize(spec, sphereAt(c0)));
  const auto now = signedDistanceField(voxelize(spec, sphereAt(c1)));
  const auto velocity = surfaceVelocity(spec, before, now, dt);
  const auto e =
      normalSpeedError(spec, now, velocity, sphereAt(c1), [&](const cv::Vec3d&) { return v; });
  std::printf(
      "translating sphere (|v| %.2f m/s, %.2f voxels a frame): mean normal-speed error "
      "%.3f m/s over %d cells, mean true normal speed %.3f m/s\n",
      cv::norm(v), cv::norm(v) * dt / spec.voxelSize, e.meanAbs, e.cells, e.meanTrue);
  ASSERT_GT(e.cells, 1000);
  EXPECT_LT(e.meanAbs, 0.3 * e.meanTrue);
}

TEST(SurfaceVelocity, TurningUserGivesTheNormalSpeedOfTheRotation) {
  // The standing user turning about the vertical axis through the pelvis at 1.5 rad/s: its
  // arms sweep (up to 1 m/s at the hands), its round torso hardly moves its surface.
  const GridSpec spec = GridSpec::cube({-0.8, 0.45, -0.8}, 1.6, 64);  // 2.5 cm voxels
  const double dt = 0.03, omega = 1.5;
  const cv::Vec3d pivot(0, 0.95, 0);
  auto turned = [&](double angle) {
    UserPose pose = standingPose();
    for (auto& joint : pose) {
      const cv::Vec3d r = joint - pivot;
      joint = pivot + cv::Vec3d(std::cos(angle) * r[0] + std::sin(angle) * r[2], r[1],
                                -std::sin(angle) * r[0] + std::cos(angle) * r[2]);
    }
    return SyntheticUser(pose);
  };
  const SyntheticUser before = turned(0), now = turned(omega * dt);
  const auto sdfBefore = signedDistanceField(before.voxelize(spec));
  const auto sdfNow = signedDistanceField(now.voxelize(spec));
  const auto velocity = surfaceVelocity(spec, sdfBefore, sdfNow, dt);
  // d/dt of the rotation above: omega x r with omega = (0, omega, 0).
  const auto e = normalSpeedError(
      spec, sdfNow, velocity, [&](const cv::Vec3d& x) { return now.signedDistance(x); },
      [&](const cv::Vec3d& x) {
        const cv::Vec3d r = x - pivot;
        return cv::Vec3d(omega * r[2], 0, -omega * r[0]);
      });
  std::printf(
      "turning user (%.1f rad/s): mean normal-speed error %.3f m/s over %d cells, mean "
      "true normal speed %.3f m/s\n",
      omega, e.meanAbs, e.cells, e.meanTrue);
  ASSERT_GT(e.cells, 1000);
  EXPECT_LT(e.meanAbs, 0.5 * e.meanTrue);
}

TEST(SurfaceVelocity, StillUserAndEmptyFramesGiveZero) {
  const GridSpec spec = GridSpec::cube({-0.7, 0.45, -0.5}, 1.4, 32);
  const auto sdf = signedDistanceField(SyntheticUser(standingPose()).voxelize(spec));
  for (float c : surfaceVelocity(spec, sdf, sdf, 0.01)) ASSERT_EQ(c, 0.0f);
  const auto empty = signedDistanceField(VoxelGrid(spec));
  for (const auto& [a, b] : {std::pair{&empty, &sdf}, std::pair{&sdf, &empty}})
    for (float c : surfaceVelocity(spec, *a, *b, 0.01)) ASSERT_EQ(c, 0.0f);
  EXPECT_EQ(surfaceVelocity(spec, sdf, sdf, 0.01).size(), 3 * spec.count());
}

TEST(SurfaceVelocity, OnlyTheBandIsComputedWithTheWholeGridsValues) {
  // The velocity is computed in the band's box only: inside the band it must equal what the
  // whole grid gives (a band wider than the grid), and be zero outside it.
  const GridSpec spec = GridSpec::cube({-0.7, -0.7, -0.7}, 1.4, 48);
  const cv::Vec3d v(0.4, 0.1, -0.2);
  auto sphereAt = [](cv::Vec3d c) {
    return [c](const cv::Vec3d& x) { return cv::norm(x - c) - 0.25; };
  };
  const auto before = signedDistanceField(voxelize(spec, sphereAt({0.1, 0, 0})));
  const auto now = signedDistanceField(voxelize(spec, sphereAt(cv::Vec3d(0.1, 0, 0) + v * 0.05)));
  SurfaceVelocitySettings band, whole;
  band.band = 0.08;
  whole.band = 1e9;
  const auto inBand = surfaceVelocity(spec, before, now, 0.05, band);
  const auto everywhere = surfaceVelocity(spec, before, now, 0.05, whole);
  int moving = 0;
  for (std::size_t c = 0; c < spec.count(); ++c)
    for (std::size_t a = 0; a < 3; ++a) {
      const float expected = std::abs(now[c]) <= band.band ? everywhere[3 * c + a] : 0.0f;
      ASSERT_EQ(inBand[3 * c + a], expected) << "cell " << c;
      if (a == 0 && expected != 0) ++moving;
    }
  EXPECT_GT(moving, 1000);
}

TEST(SurfaceVelocity, ATimeAverageReadsASlowSurfacesVoxelStepsAsItsSpeed) {
  // A sphere moving 0.2 voxels a frame: its voxel model steps a whole voxel every 5 frames. One
  // frame's change reads the step as a voxel per frame (5x its speed) and the frames between as
  // still; averaged over 10 frames the estimate stays near the true speed.
  const GridSpec spec = GridSpec::cube({-0.7, -0.7, -0.7}, 1.4, 56);  // 2.5 cm voxels
  const double dt = 0.01, speed = 0.2 * spec.voxelSize / dt;          // 0.5 m/s
  auto sdfAt = [&](int frame) {
    const cv::Vec3d c(-0.1 + speed * dt * frame, 0.013, -0.007);
    return signedDistanceField(
        voxelize(spec, [c](const cv::Vec3d& x) { return cv::norm(x - c) - 0.3; }));
  };
  // The estimated speed along +x at the sphere's leading point, frame by frame.
  auto leadingSpeed = [&](const std::vector<float>& velocity, int frame) {
    const cv::Vec3d lead(-0.1 + speed * dt * frame + 0.3, 0.013, -0.007);
    const int i = static_cast<int>(std::lround((lead[0] - spec.origin[0]) / spec.voxelSize - 0.5));
    const int j = static_cast<int>(std::lround((lead[1] - spec.origin[1]) / spec.voxelSize - 0.5));
    const int k = static_cast<int>(std::lround((lead[2] - spec.origin[2]) / spec.voxelSize - 0.5));
    return static_cast<double>(velocity[3 * spec.index(i, j, k)]);
  };
  SurfaceVelocitySettings one, ten;
  ten.frames = 10;
  SurfaceChangeHistory history;
  double peakOne = 0, peakTen = 0, meanTen = 0;
  int counted = 0;
  std::vector<float> before = sdfAt(0);
  for (int frame = 1; frame <= 40; ++frame) {
    const std::vector<float> now = sdfAt(frame);
    const double a = leadingSpeed(surfaceVelocity(spec, before, now, dt, one), frame);
    const double b = leadingSpeed(surfaceVelocity(spec, before, now, dt, ten, &history), frame);
    before = now;
    if (frame <= 20) continue;  // the average has settled
    peakOne = std::max(peakOne, a);
    peakTen = std::max(peakTen, b);
    meanTen += b;
    ++counted;
  }
  meanTen /= counted;
  std::printf(
      "sphere at %.2f m/s (0.2 voxels a frame): peak estimate %.2f m/s from one frame, %.2f "
      "m/s averaged over 10 (mean %.2f)\n",
      speed, peakOne, peakTen, meanTen);
  EXPECT_GT(peakOne, 2.5 * speed) << "one frame reads a voxel step";
  EXPECT_LT(peakTen, 2.0 * speed);
  EXPECT_GT(meanTen, 0.5 * speed);
  EXPECT_LT(meanTen, 1.5 * speed);
}

msg::MessageView finish(msg::MessageBuilder& builder) {
  const std::size_t size = builder.finish();
  EXPECT_GT(size, 0u);
  auto view = msg::MessageView::parse(builder.bytes().first(size));
  EXPECT_TRUE(view.ok()) << view.error().message;
  return *view;
}

TEST(UserObject, RoundTripsThroughAMessageToWhatInteractorsSample) {
  const GridSpec spec = GridSpec::cube({-0.5, -0.5, -0.5}, 1.0, 40);
  const cv::Vec3d centre(0.05, -0.02, 0.01);
  auto sphere = [&](const cv::Vec3d& x) { return cv::norm(x - centre) - 0.25; };
  const VoxelGrid grid = voxelize(spec, sphere);
  UserFrame frame = describeUser(grid);
  frame.velocity.assign(3 * spec.count(), 0.0f);
  for (std::size_t c = 0; c < spec.count(); ++c) frame.velocity[3 * c] = 0.75f;
  EXPECT_NEAR(frame.position[0], centre[0], 1e-3);
  EXPECT_NEAR(frame.bounds.min[1], centre[1] - 0.25, spec.voxelSize);
  EXPECT_NEAR(frame.bounds.max[2], centre[2] + 0.25, spec.voxelSize);
  EXPECT_TRUE(frame.mesh.isClosed());

  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  writeUser(builder, {11, 12, 13, 14}, frame, true);
  UserCopy copy;
  ASSERT_TRUE(copy.apply(finish(builder)).ok());
  const auto users = copy.ready();
  ASSERT_EQ(users.size(), 1u);
  const UserSurface& user = *users.at(11);
  EXPECT_EQ(user.position, frame.position);
  // Within a voxel of the analytic distance inside, near and beyond the grid.
  for (const msg::Vec3& p : {msg::Vec3{0.15, -0.02, 0.01}, msg::Vec3{0.3, 0.0, 0.0},
                             msg::Vec3{0.1, 0.2, -0.1}, msg::Vec3{0.9, 0.0, 0.0}})
    EXPECT_NEAR(user.distance(p), sphere({p[0], p[1], p[2]}), spec.voxelSize) << p[0];
  const msg::Vec3 n = user.normal({0.35, -0.02, 0.01});
  EXPECT_NEAR(n[0], 1.0, 0.05);
  EXPECT_NEAR(user.velocityAt({0.3, 0.0, 0.0})[0], 0.75, 1e-6);
  EXPECT_EQ(user.velocityAt({2.0, 0.0, 0.0}), (msg::Vec3{0, 0, 0}));

  // An update moves it; a delete removes it.
  builder.reset();
  frame.position = {0.5, 0.5, 0.5};
  writeUser(builder, {11, 12, 13, 14}, frame, false);
  ASSERT_TRUE(copy.apply(finish(builder)).ok());
  EXPECT_EQ(copy.all().at(11).position, frame.position);
  builder.reset();
  builder.addDelete(11, msg::userType());
  ASSERT_TRUE(copy.apply(finish(builder)).ok());
  EXPECT_TRUE(copy.ready().empty());
}

TEST(UserObject, ABandedFrameIsTheWholeFrameWithItsFieldClampedAndTheSameMesh) {
  const GridSpec spec = GridSpec::cube({-0.5, -0.5, -0.5}, 1.0, 48);
  auto capsule = [](const cv::Vec3d& x) {
    const double t = std::clamp(x[0], -0.2, 0.2);
    return cv::norm(x - cv::Vec3d(t, 0.05, 0.0)) - 0.1;
  };
  const VoxelGrid grid = voxelize(spec, capsule);
  const UserFrame whole = describeUser(grid);
  const double band = 0.15;
  const UserFrame banded = describeUser(grid, band, 2);
  ASSERT_EQ(banded.sdf.size(), whole.sdf.size());
  std::size_t clamped = 0;
  for (std::size_t c = 0; c < whole.sdf.size(); ++c) {
    EXPECT_EQ(banded.sdf[c], std::min(whole.sdf[c], static_cast<float>(band))) << "voxel " << c;
    clamped += whole.sdf[c] > static_cast<float>(band) ? 1 : 0;
  }
  EXPECT_GT(clamped, spec.count() / 4) << "the band must clamp part of this grid";
  EXPECT_EQ(banded.mesh.vertices, whole.mesh.vertices);
  EXPECT_EQ(banded.mesh.triangles, whole.mesh.triangles);
  EXPECT_EQ(banded.position, whole.position);
  EXPECT_EQ(banded.voxels, whole.voxels);
}

TEST(UserObject, AFieldOfTheWrongKindOrGridIsAnErrorNamingTheUser) {
  const GridSpec spec = GridSpec::cube({0, 0, 0}, 1.0, 4);
  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  std::vector<float> three(3 * spec.count(), 0.0f), one(spec.count(), 1.0f);
  builder.addField(13, true, {4, 4, 4}, 3, {0, 0, 0}, 0.25, three);  // the sdf as vectors
  builder.addObject(11, msg::userType(), msg::ObjectOp::Add)
      .set(msg::UserParam::kSdf, std::uint64_t{13});
  UserCopy copy;
  auto status = copy.apply(finish(builder));
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("user 11: resource 13 (sdf) is not a scalar field"),
            std::string::npos)
      << status.error().message;
  EXPECT_TRUE(copy.ready().empty());

  builder.reset();
  builder.addField(13, true, {4, 4, 4}, 1, {0, 0, 0}, 0.25, one);
  builder.addField(14, true, {2, 2, 2}, 3, {0, 0, 0}, 0.5, std::span(three).first(24));
  builder.addObject(11, msg::userType(), msg::ObjectOp::Update)
      .set(msg::UserParam::kVelocityField, std::uint64_t{14});
  status = copy.apply(finish(builder));
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("another grid"), std::string::npos)
      << status.error().message;
  EXPECT_EQ(copy.ready().size(), 1u);  // the distance field arrived; the velocity did not
  EXPECT_EQ(copy.ready().at(11)->velocityAt({0.5, 0.5, 0.5}), (msg::Vec3{0, 0, 0}));
}

}  // namespace
}  // namespace vrflow::camera
