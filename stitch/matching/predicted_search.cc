// Search::kPredicted (strip_candidates.h). The nominal mappings predict where a pixel of a lies in
// b to within the misplacement the search margin absorbs, so b needs no keypoints and no
// descriptors (issue 35: SIFT and brute-force matching were about 80 % of a frame's time).
// Per grid cell the strongest Foerstner points of a's window (on the raw grey values: the per-cell
// choice, not a global threshold, spreads them over low-contrast fields); for each, the patch of b
// around the prediction is resampled into a's geometry through the nominal local affine map, and
// the template of a is located in it by normalised cross-correlation (OpenCV TM_CCOEFF_NORMED,
// gain / offset free) with a parabolic sub-pixel peak. The caller's RANSAC drops wrong peaks
// (repetitive texture); least-squares matching then refines the survivors.
#include "stitch/image_io/cv_view.h"
#include "stitch/matching/strip_candidates.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

namespace aerocal::stitch {
namespace {

// The global Foerstner threshold as a fraction of the mean weight: low, since each cell keeps its
// own strongest points; it only drops flat, noise-only pixels.
constexpr double kCellWeightFactor = 0.05;

// d(uv_b) / d(uv_a) of the nominal prediction at uv_a (central differences over 1 px: the
// mappings are affine or smooth polynomials).
Eigen::Matrix2d PredictionJacobian(const calib::SubimageMapping& sa,
                                   const calib::SubimageMapping& sb,
                                   const Eigen::Vector2d& uv_a) {
  Eigen::Matrix2d j;
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector2d step = Eigen::Vector2d::Unit(k);
    j.col(k) = (PredictInB(sa, sb, uv_a + step) - PredictInB(sa, sb, uv_a - step)) / 2.0;
  }
  return j;
}

// Offset of the correlation peak from the result's centre, with a parabola through the peak and
// its neighbours per axis; nullopt when the peak is on the border (the match may lie beyond the
// search range) or below `min_ncc`.
std::optional<Eigen::Vector2d> PeakOffset(const cv::Mat& ncc, double min_ncc, double* peak) {
  double max_value = 0;
  cv::Point at;
  cv::minMaxLoc(ncc, nullptr, &max_value, nullptr, &at);
  *peak = max_value;
  if (!(max_value >= min_ncc) || at.x < 1 || at.y < 1 || at.x >= ncc.cols - 1 ||
      at.y >= ncc.rows - 1)
    return std::nullopt;
  auto vertex = [](double left, double centre, double right) {
    const double curvature = left - 2.0 * centre + right;
    return curvature < 0 ? 0.5 * (left - right) / curvature : 0.0;
  };
  const double dx = vertex(
      ncc.at<float>(at.y, at.x - 1), ncc.at<float>(at.y, at.x), ncc.at<float>(at.y, at.x + 1));
  const double dy = vertex(
      ncc.at<float>(at.y - 1, at.x), ncc.at<float>(at.y, at.x), ncc.at<float>(at.y + 1, at.x));
  return Eigen::Vector2d(at.x + dx - (ncc.cols - 1) / 2, at.y + dy - (ncc.rows - 1) / 2);
}

// Position in b of a's template at integer pixel p_a, searched within `search` px (in a's
// geometry) of `predicted`; nullopt when the template leaves a or no acceptable peak is found.
// Near b's border the search window is moved inwards so that it stays inside b (a match beyond the
// border could not be measured anyway); the prediction must stay inside the moved window.
std::optional<Eigen::Vector2d> FindByCorrelation(const GrayImage& a,
                                                 const Eigen::Vector2i& p_a,
                                                 const GrayImage& b,
                                                 const Eigen::Vector2d& predicted,
                                                 const Eigen::Matrix2d& b_per_a,
                                                 int half,
                                                 int search,
                                                 double min_ncc,
                                                 double* ncc_peak) {
  if (p_a.x() < half || p_a.y() < half || p_a.x() + half >= a.cols() || p_a.y() + half >= a.rows())
    return std::nullopt;
  const int reach = half + search, side = 2 * reach + 1;
  // Half extents in b of the patch, and its centre clamped into b.
  const Eigen::Vector2d extent = reach * b_per_a.cwiseAbs().rowwise().sum();
  const Eigen::Vector2d last(b.cols() - 1, b.rows() - 1);
  if ((2 * extent.array() > last.array()).any()) return std::nullopt;
  const Eigen::Vector2d centre = predicted.cwiseMax(extent).cwiseMin(last - extent);
  const Eigen::Vector2d shift = b_per_a.inverse() * (predicted - centre);  // a px
  if (shift.cwiseAbs().maxCoeff() > search - 1) return std::nullopt;
  // Patch pixel (i, j) is a-offset o = (j - reach, i - reach) from the centre, at
  // centre + b_per_a o in b.
  const Eigen::Vector2d origin = centre - b_per_a * Eigen::Vector2d(reach, reach);
  const cv::Matx23d patch_to_b(
      b_per_a(0, 0), b_per_a(0, 1), origin.x(), b_per_a(1, 0), b_per_a(1, 1), origin.y());
  cv::Mat patch, ncc;
  cv::warpAffine(CvView(b),
                 patch,
                 patch_to_b,
                 cv::Size(side, side),
                 cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                 cv::BORDER_REPLICATE);
  const cv::Mat templ =
      CvView(a)(cv::Rect(p_a.x() - half, p_a.y() - half, 2 * half + 1, 2 * half + 1));
  cv::matchTemplate(patch, templ, ncc, cv::TM_CCOEFF_NORMED);
  const std::optional<Eigen::Vector2d> offset = PeakOffset(ncc, min_ncc, ncc_peak);
  if (!offset) return std::nullopt;
  return centre + b_per_a * *offset;
}

// The strongest Foerstner points of a's window per grid cell of the strip (cells in virtual px, as
// the caller's thinning), strongest first within a cell; integer pixels of a. Per cell
// `candidates_per_cell`, more in strips of few cells (the small corner overlaps) so that the strip
// offers RANSAC three times its minimum of inliers.
std::vector<Eigen::Vector2i> PointsPerCell(const GrayImage& image_a,
                                           const calib::SubimageMapping& sa,
                                           const OverlapStrip& strip,
                                           const MatchOptions& options,
                                           int* detected) {
  const cv::Rect rect = PixelRect(strip.window_in_a);
  FoerstnerOptions foerstner = options.foerstner;
  foerstner.weight_factor = kCellWeightFactor;
  foerstner.max_points = rect.area();
  const std::vector<InterestPoint> points =
      DetectFoerstner(image_a.block(rect.y, rect.x, rect.height, rect.width), foerstner);
  *detected = static_cast<int>(points.size());
  const Eigen::Vector2d cells_xy = (strip.in_virtual.sizes() / options.cell_px).array().ceil();
  const int cells = std::max(1, static_cast<int>(cells_xy.prod()));
  const int per_cell =
      std::max(options.candidates_per_cell, (3 * options.ransac.min_inliers + cells - 1) / cells);
  std::map<std::pair<long, long>, int> taken;  // cell -> points kept
  std::vector<Eigen::Vector2i> out;
  for (const InterestPoint& p : points) {  // strongest first
    const Eigen::Vector2d uv(p.position.x() + rect.x, p.position.y() + rect.y);
    const Eigen::Vector2d cell = (sa.VirtualFromSub(uv) - strip.in_virtual.min()) / options.cell_px;
    int& kept = taken[{std::lround(std::floor(cell.y())), std::lround(std::floor(cell.x()))}];
    if (kept >= per_cell) continue;
    ++kept;
    out.push_back(uv.cast<int>());
  }
  return out;
}

}  // namespace

StripCandidates PredictedCandidates(const calib::Camera& camera,
                                    const std::vector<GrayImage>& images,
                                    const OverlapStrip& strip,
                                    const MatchOptions& options) {
  const calib::SubimageMapping& sa = camera.subimages[strip.a];
  const calib::SubimageMapping& sb = camera.subimages[strip.b];
  StripCandidates out;
  const std::vector<Eigen::Vector2i> points =
      PointsPerCell(images[strip.a], sa, strip, options, &out.keypoints_a);
  const int search = static_cast<int>(std::ceil(options.margin_px));
  for (const Eigen::Vector2i& p_a : points) {
    const Eigen::Vector2d uv_a = p_a.cast<double>();
    double peak = 0;
    const std::optional<Eigen::Vector2d> uv_b = FindByCorrelation(images[strip.a],
                                                                  p_a,
                                                                  images[strip.b],
                                                                  PredictInB(sa, sb, uv_a),
                                                                  PredictionJacobian(sa, sb, uv_a),
                                                                  options.lsm.half_size_px,
                                                                  search,
                                                                  options.min_ncc,
                                                                  &peak);
    if (!uv_b) continue;
    out.in_a.push_back(uv_a);
    out.in_b.push_back(*uv_b);
    out.score.push_back(1.0 - peak);
  }
  return out;
}

}  // namespace aerocal::stitch
