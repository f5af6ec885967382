#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "reference_chain.hpp"

namespace vrflow::camera::reference {

namespace {

constexpr int kTopBlock = 16;  // voxels per edge of the coarsest blocks

// One camera prepared for a frame: its projection and the integral image of its mask.
struct PreparedView {
  cv::Matx34d projection;
  cv::Mat mask;      // CV_8UC1, 0 or 1
  cv::Mat integral;  // CV_32S, (rows+1) x (cols+1)

  // Rounded pixel of a world point, or false when it is behind the camera.
  bool pixel(const cv::Vec3d& p, double& u, double& v) const {
    const cv::Vec4d h(p[0], p[1], p[2], 1.0);
    const cv::Vec3d q = projection * h;
    if (q[2] <= 0) return false;
    u = q[0] / q[2];
    v = q[1] / q[2];
    return true;
  }
};

enum class Decision { kOutside, kInside, kMixed };

class Carver {
 public:
  Carver(const std::vector<PreparedView>& views, VoxelGrid& hull, int zBegin, int zEnd,
         CarveStats& stats)
      : views_(views), hull_(hull), spec_(hull.spec), zBegin_(zBegin), zEnd_(zEnd), stats_(stats) {}

  void run() {
    for (int k = zBegin_; k < zEnd_; k += kTopBlock)
      for (int j = 0; j < spec_.ny; j += kTopBlock)
        for (int i = 0; i < spec_.nx; i += kTopBlock)
          visit({i, j, k}, {std::min(i + kTopBlock, spec_.nx), std::min(j + kTopBlock, spec_.ny),
                            std::min(k + kTopBlock, zEnd_)});
  }

 private:
  // Blocks [lo, hi) of voxels; voxel by voxel at the finest level.
  void visit(const cv::Vec3i& lo, const cv::Vec3i& hi) {
    const cv::Vec3i extent = hi - lo;
    if (extent[0] * extent[1] * extent[2] == 1) {
      ++stats_.voxelsTested;
      hull_.occupied[spec_.index(lo[0], lo[1], lo[2])] = voxelInside(lo) ? 1 : 0;
      return;
    }
    const Decision decision = classify(lo, hi);
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
      if (!empty) visit(a, b);
    }
  }

  bool voxelInside(const cv::Vec3i& v) const {
    const cv::Vec3d p = spec_.centre(v[0], v[1], v[2]);
    for (const PreparedView& view : views_) {
      double u = 0, w = 0;
      if (!view.pixel(p, u, w)) return false;
      const long x = std::lround(u), y = std::lround(w);
      if (x < 0 || y < 0 || x >= view.mask.cols || y >= view.mask.rows) return false;
      if (!view.mask.at<std::uint8_t>(static_cast<int>(y), static_cast<int>(x))) return false;
    }
    return true;
  }

  // The block's voxel centres span a box; its 8 corners' projections bound theirs (a pinhole
  // camera maps the box to the convex hull of the projected corners).
  Decision classify(const cv::Vec3i& lo, const cv::Vec3i& hi) const {
    const cv::Vec3d minimum = spec_.centre(lo[0], lo[1], lo[2]);
    const cv::Vec3d maximum = spec_.centre(hi[0] - 1, hi[1] - 1, hi[2] - 1);
    bool insideAll = true;
    for (const PreparedView& view : views_) {
      double minU = 1e30, minV = 1e30, maxU = -1e30, maxV = -1e30;
      for (int c = 0; c < 8; ++c) {
        const cv::Vec3d p((c & 1) ? maximum[0] : minimum[0], (c & 2) ? maximum[1] : minimum[1],
                          (c & 4) ? maximum[2] : minimum[2]);
        double u = 0, v = 0;
        if (!view.pixel(p, u, v)) return Decision::kMixed;
        minU = std::min(minU, u), maxU = std::max(maxU, u);
        minV = std::min(minV, v), maxV = std::max(maxV, v);
      }
      // Pixels the centres can round to: [round(min), round(max)], inclusive.
      const double x0 = std::floor(minU + 0.5), x1 = std::floor(maxU + 0.5);
      const double y0 = std::floor(minV + 0.5), y1 = std::floor(maxV + 0.5);
      const bool whollyInImage = x0 >= 0 && y0 >= 0 && x1 < view.mask.cols && y1 < view.mask.rows;
      const int cx0 = static_cast<int>(std::clamp(x0, 0.0, double(view.mask.cols)));
      const int cx1 = static_cast<int>(std::clamp(x1 + 1, 0.0, double(view.mask.cols)));
      const int cy0 = static_cast<int>(std::clamp(y0, 0.0, double(view.mask.rows)));
      const int cy1 = static_cast<int>(std::clamp(y1 + 1, 0.0, double(view.mask.rows)));
      if (cx0 >= cx1 || cy0 >= cy1) return Decision::kOutside;  // all outside the image
      const int count = view.integral.at<int>(cy1, cx1) - view.integral.at<int>(cy0, cx1) -
                        view.integral.at<int>(cy1, cx0) + view.integral.at<int>(cy0, cx0);
      if (count == 0) return Decision::kOutside;
      if (!whollyInImage || count != (cx1 - cx0) * (cy1 - cy0)) insideAll = false;
    }
    return insideAll ? Decision::kInside : Decision::kMixed;
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

}  // namespace

void carveVisualHull(const std::vector<MaskView>& views, VoxelGrid& hull) {
  std::vector<PreparedView> prepared(views.size());
  for (std::size_t i = 0; i < views.size(); ++i) {
    prepared[i].projection = views[i].camera->projection();
    cv::threshold(views[i].mask, prepared[i].mask, 0, 1, cv::THRESH_BINARY);
    cv::integral(prepared[i].mask, prepared[i].integral, CV_32S);
  }
  CarveStats stats;
  Carver(prepared, hull, 0, hull.spec.nz, stats).run();
}

}  // namespace vrflow::camera::reference
