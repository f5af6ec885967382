#include "vrflow/camera/visual_hull.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>

#include "parallel_parts.hpp"

namespace vrflow::camera {

namespace {

constexpr int kTopBlock = 16;    // voxels per edge of the coarsest blocks
constexpr int kMaxCameras = 64;  // the cameras still undecided in a block are bits of a word
// Projected block corners are widened by this (pixels) so that the rounding of a centre's own
// projection, computed another way, can never fall outside the rectangle.
constexpr double kCornerSlack = 1e-6;

using CameraSet = std::uint64_t;

// One camera prepared for a frame: the terms of its projection along each grid axis, and its
// mask and the mask's integral image. The projection of a voxel centre is affine along each axis
// before the perspective divide: row r of P (x, y, z, 1) is ((a[r][i] + b[r][j]) + c[r][k]) +
// d[r], summed in the order of cv::Matx's product so that every voxel rounds as it always did.
struct PreparedView {
  std::array<std::vector<double>, 3> a, b, c;
  std::array<double, 3> d{};
  cv::Mat mask;      // CV_8UC1, 0 or 1
  cv::Mat integral;  // CV_32S, (rows+1) x (cols+1)

  PreparedView(const MaskView& view, const GridSpec& spec) {
    const cv::Matx34d projection = view.camera->projection();
    for (int r = 0; r < 3; ++r) {
      const auto row = static_cast<std::size_t>(r);
      a[row].resize(static_cast<std::size_t>(spec.nx));
      b[row].resize(static_cast<std::size_t>(spec.ny));
      c[row].resize(static_cast<std::size_t>(spec.nz));
      for (int i = 0; i < spec.nx; ++i)
        a[row][static_cast<std::size_t>(i)] =
            projection(r, 0) * (spec.origin[0] + (i + 0.5) * spec.voxelSize);
      for (int j = 0; j < spec.ny; ++j)
        b[row][static_cast<std::size_t>(j)] =
            projection(r, 1) * (spec.origin[1] + (j + 0.5) * spec.voxelSize);
      for (int k = 0; k < spec.nz; ++k)
        c[row][static_cast<std::size_t>(k)] =
            projection(r, 2) * (spec.origin[2] + (k + 0.5) * spec.voxelSize);
      d[row] = projection(r, 3) * 1.0;
    }
    cv::threshold(view.mask, mask, 0, 1, cv::THRESH_BINARY);
    cv::integral(mask, integral, CV_32S);
  }

  double term(std::size_t r, int i, int j, int k) const {
    return ((a[r][static_cast<std::size_t>(i)] + b[r][static_cast<std::size_t>(j)]) +
            c[r][static_cast<std::size_t>(k)]) +
           d[r];
  }

  // Whether voxel (i, j, k)'s centre rounds to a mask pixel (in front of the camera).
  bool sees(int i, int j, int k) const {
    const double q2 = term(2, i, j, k);
    if (q2 <= 0) return false;
    const long x = std::lround(term(0, i, j, k) / q2), y = std::lround(term(1, i, j, k) / q2);
    if (x < 0 || y < 0 || x >= mask.cols || y >= mask.rows) return false;
    return mask.at<std::uint8_t>(static_cast<int>(y), static_cast<int>(x)) != 0;
  }
};

enum class Decision { kOutside, kInside, kMixed };

// Carves the blocks of one range of z: a block is split in 8 until it is decided whole or is
// one voxel. Each block carries the cameras that have not yet seen all of it inside their mask:
// a camera whose mask is full over the block's footprint is not asked again below it.
class Carver {
 public:
  Carver(const std::vector<PreparedView>& views, VoxelGrid& hull, int zBegin, int zEnd,
         CarveStats& stats)
      : views_(views), hull_(hull), spec_(hull.spec), zBegin_(zBegin), zEnd_(zEnd), stats_(stats) {}

  void run() {
    const CameraSet all =
        views_.size() == kMaxCameras ? ~CameraSet{0} : (CameraSet{1} << views_.size()) - 1;
    for (int k = zBegin_; k < zEnd_; k += kTopBlock)
      for (int j = 0; j < spec_.ny; j += kTopBlock)
        for (int i = 0; i < spec_.nx; i += kTopBlock)
          visit({i, j, k},
                {std::min(i + kTopBlock, spec_.nx), std::min(j + kTopBlock, spec_.ny),
                 std::min(k + kTopBlock, zEnd_)},
                all);
  }

 private:
  // Blocks [lo, hi) of voxels; voxel by voxel at the finest level.
  void visit(const cv::Vec3i& lo, const cv::Vec3i& hi, CameraSet active) {
    const cv::Vec3i extent = hi - lo;
    if (extent[0] * extent[1] * extent[2] == 1) {
      ++stats_.voxelsTested;
      hull_.occupied[spec_.index(lo[0], lo[1], lo[2])] = voxelInside(lo, active) ? 1 : 0;
      return;
    }
    const Decision decision = classify(lo, hi, active);
    if (decision != Decision::kMixed) {
      ++stats_.blocksDecided;
      fill(lo, hi, decision == Decision::kInside ? 1 : 0);
      return;
    }
    // Halve every edge longer than one voxel.
    const cv::Vec3i mid((lo[0] + hi[0] + 1) / 2, (lo[1] + hi[1] + 1) / 2, (lo[2] + hi[2] + 1) / 2);
    for (int c = 0; c < 8; ++c) {
      cv::Vec3i a, b;
      bool empty = false;
      for (int axis = 0; axis < 3; ++axis) {
        const bool upper = (c >> axis) & 1;
        if (extent[axis] == 1 && upper) empty = true;
        a[axis] = upper ? mid[axis] : lo[axis];
        b[axis] = (upper || extent[axis] == 1) ? hi[axis] : mid[axis];
      }
      if (!empty) visit(a, b, active);
    }
  }

  bool voxelInside(const cv::Vec3i& v, CameraSet active) const {
    for (; active; active &= active - 1)
      if (!views_[static_cast<std::size_t>(std::countr_zero(active))].sees(v[0], v[1], v[2]))
        return false;
    return true;
  }

  // The block's voxel centres span a box; its 8 corners' projections bound theirs (a pinhole
  // camera maps the box to the convex hull of the projected corners). Cameras whose mask is
  // full over the rectangle leave `active`.
  Decision classify(const cv::Vec3i& lo, const cv::Vec3i& hi, CameraSet& active) const {
    const int corner[2][3] = {{lo[0], lo[1], lo[2]}, {hi[0] - 1, hi[1] - 1, hi[2] - 1}};
    CameraSet full = 0;
    for (CameraSet rest = active; rest; rest &= rest - 1) {
      const int index = std::countr_zero(rest);
      const PreparedView& view = views_[static_cast<std::size_t>(index)];
      double minU = 1e30, minV = 1e30, maxU = -1e30, maxV = -1e30;
      bool behind = false;
      for (int c = 0; c < 8; ++c) {
        const int i = corner[c & 1][0], j = corner[(c >> 1) & 1][1], k = corner[(c >> 2) & 1][2];
        const double q2 = view.term(2, i, j, k);
        if (q2 <= 0) {
          behind = true;
          break;
        }
        const double inverse = 1.0 / q2;
        const double u = view.term(0, i, j, k) * inverse, v = view.term(1, i, j, k) * inverse;
        minU = std::min(minU, u), maxU = std::max(maxU, u);
        minV = std::min(minV, v), maxV = std::max(maxV, v);
      }
      if (behind) continue;  // this camera cannot decide the block
      // Pixels the centres can round to: [round(min), round(max)], inclusive.
      const double x0 = std::floor(minU + 0.5 - kCornerSlack);
      const double x1 = std::floor(maxU + 0.5 + kCornerSlack);
      const double y0 = std::floor(minV + 0.5 - kCornerSlack);
      const double y1 = std::floor(maxV + 0.5 + kCornerSlack);
      const bool whollyInImage = minU - kCornerSlack > 0.5 && minV - kCornerSlack > 0.5 &&
                                 x1 < view.mask.cols && y1 < view.mask.rows;
      const int cx0 = static_cast<int>(std::clamp(x0, 0.0, double(view.mask.cols)));
      const int cx1 = static_cast<int>(std::clamp(x1 + 1, 0.0, double(view.mask.cols)));
      const int cy0 = static_cast<int>(std::clamp(y0, 0.0, double(view.mask.rows)));
      const int cy1 = static_cast<int>(std::clamp(y1 + 1, 0.0, double(view.mask.rows)));
      if (cx0 >= cx1 || cy0 >= cy1) return Decision::kOutside;  // all outside the image
      const int count = view.integral.at<int>(cy1, cx1) - view.integral.at<int>(cy0, cx1) -
                        view.integral.at<int>(cy1, cx0) + view.integral.at<int>(cy0, cx0);
      if (count == 0) return Decision::kOutside;
      if (whollyInImage && count == (cx1 - cx0) * (cy1 - cy0)) full |= CameraSet{1} << index;
    }
    active &= ~full;
    return active == 0 ? Decision::kInside : Decision::kMixed;
  }

  void fill(const cv::Vec3i& lo, const cv::Vec3i& hi, std::uint8_t value) {
    for (int k = lo[2]; k < hi[2]; ++k)
      for (int j = lo[1]; j < hi[1]; ++j) {
        std::uint8_t* row = &hull_.occupied[spec_.index(lo[0], j, k)];
        std::fill(row, row + (hi[0] - lo[0]), value);
      }
  }

  const std::vector<PreparedView>& views_;
  VoxelGrid& hull_;
  const GridSpec& spec_;
  int zBegin_, zEnd_;
  CarveStats& stats_;
};

Status checkViews(const std::vector<MaskView>& views) {
  if (views.empty()) return makeError("no camera to carve the visual hull with");
  if (views.size() > kMaxCameras)
    return makeError(std::to_string(views.size()) + " cameras: the visual hull takes at most " +
                     std::to_string(kMaxCameras));
  for (std::size_t i = 0; i < views.size(); ++i) {
    const MaskView& view = views[i];
    if (view.mask.type() != CV_8UC1 || view.mask.size() != view.camera->imageSize)
      return makeError("camera " + std::to_string(i) + ": mask of " +
                       std::to_string(view.mask.cols) + "x" + std::to_string(view.mask.rows) +
                       " (" + cv::typeToString(view.mask.type()) + ") where the calibration says " +
                       std::to_string(view.camera->imageSize.width) + "x" +
                       std::to_string(view.camera->imageSize.height) + " CV_8UC1");
  }
  return {};
}

}  // namespace

Status carveVisualHull(const std::vector<MaskView>& views, int zBegin, int zEnd, VoxelGrid& hull,
                       CarveStats* stats, int threads) {
  if (auto status = checkViews(views); !status) return status;
  if (zBegin < 0 || zEnd > hull.spec.nz || zBegin >= zEnd)
    return makeError("slab [" + std::to_string(zBegin) + ", " + std::to_string(zEnd) +
                     ") is not a non-empty range of the grid's " + std::to_string(hull.spec.nz) +
                     " z layers");
  // Each camera's terms and integral image on its own thread (the same values on any count).
  std::vector<std::optional<PreparedView>> made(views.size());
  forParts(threads, views.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) made[v].emplace(views[v], hull.spec);
  });
  std::vector<PreparedView> prepared;
  prepared.reserve(views.size());
  for (auto& view : made) prepared.push_back(std::move(*view));
  // Parts are whole layers of top blocks, each carved alone; the counts are summed in order.
  const auto layers = static_cast<std::size_t>((zEnd - zBegin + kTopBlock - 1) / kTopBlock);
  std::vector<CarveStats> partStats(layers);
  forParts(threads, layers, [&](std::size_t begin, std::size_t end) {
    const int z0 = zBegin + static_cast<int>(begin) * kTopBlock;
    const int z1 = std::min(zEnd, zBegin + static_cast<int>(end) * kTopBlock);
    Carver(prepared, hull, z0, z1, partStats[begin]).run();
  });
  if (stats)
    for (const CarveStats& part : partStats) {
      stats->blocksDecided += part.blocksDecided;
      stats->voxelsTested += part.voxelsTested;
    }
  return {};
}

Result<VoxelGrid> carveVisualHull(const std::vector<MaskView>& views, const GridSpec& spec,
                                  CarveStats* stats, int threads) {
  VoxelGrid hull(spec);
  if (auto status = carveVisualHull(views, 0, spec.nz, hull, stats, threads); !status)
    return status.error();
  return hull;
}

Result<VoxelGrid> carveVisualHullBaseline(const std::vector<MaskView>& views,
                                          const GridSpec& spec) {
  if (auto status = checkViews(views); !status) return status.error();
  VoxelGrid hull(spec);
  std::vector<cv::Point3d> centres;
  centres.reserve(spec.count());
  for (int k = 0; k < spec.nz; ++k)
    for (int j = 0; j < spec.ny; ++j)
      for (int i = 0; i < spec.nx; ++i) centres.emplace_back(spec.centre(i, j, k));
  std::fill(hull.occupied.begin(), hull.occupied.end(), std::uint8_t{1});
  std::vector<cv::Point2d> pixels;
  for (const MaskView& view : views) {
    cv::Vec3d rvec;
    cv::Rodrigues(view.camera->rotation, rvec);
    cv::projectPoints(centres, rvec, view.camera->translation, view.camera->cameraMatrix,
                      view.camera->distortion, pixels);
    for (std::size_t n = 0; n < centres.size(); ++n) {
      const cv::Vec3d c = view.camera->rotation * cv::Vec3d(centres[n]) + view.camera->translation;
      const long x = std::lround(pixels[n].x), y = std::lround(pixels[n].y);
      if (c[2] <= 0 || x < 0 || y < 0 || x >= view.mask.cols || y >= view.mask.rows ||
          !view.mask.at<std::uint8_t>(static_cast<int>(y), static_cast<int>(x)))
        hull.occupied[n] = 0;
    }
  }
  return hull;
}

cv::Mat undistortMask(const cv::Mat& mask, const CameraCalibration& camera) {
  cv::Mat out;
  cv::undistort(mask, out, camera.cameraMatrix, camera.distortion);
  cv::threshold(out, out, 127, 255, cv::THRESH_BINARY);
  return out;
}

}  // namespace vrflow::camera
