#include "stitch/matching/overlap_matcher.h"

#include "calib/core/error.h"
#include "stitch/matching/overlap_strips.h"

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sys/stat.h>
#include <tuple>

namespace aerocal::stitch {
namespace {

// Keypoints of one search window, in full sub-image pixels, with descriptors (one row each).
struct WindowFeatures {
  std::vector<Eigen::Vector2d> positions;
  cv::Mat descriptors;
};

// Integer pixel rectangle [x0, x1) x [y0, y1) covering a window box.
cv::Rect PixelRect(const Eigen::AlignedBox2d& box) {
  const int x0 = static_cast<int>(std::floor(box.min().x()));
  const int y0 = static_cast<int>(std::floor(box.min().y()));
  const int x1 = static_cast<int>(std::ceil(box.max().x())) + 1;
  const int y1 = static_cast<int>(std::ceil(box.max().y())) + 1;
  return {x0, y0, x1 - x0, y1 - y0};
}

// Linear stretch of mean +- 3 std to 0..255 (SIFT wants 8 bit; this makes it gain/offset free).
cv::Mat To8Bit(const cv::Mat& window) {
  cv::Scalar mean, stddev;
  cv::meanStdDev(window, mean, stddev);
  const double scale = stddev[0] > 0 ? 255.0 / (6.0 * stddev[0]) : 1.0;
  cv::Mat out;
  window.convertTo(out, CV_8U, scale, 127.5 - scale * mean[0]);
  return out;
}

bool KeypointBefore(const cv::KeyPoint& x, const cv::KeyPoint& y) {
  return std::make_tuple(-x.response, x.pt.y, x.pt.x, x.size, x.angle, x.octave) <
         std::make_tuple(-y.response, y.pt.y, y.pt.x, y.size, y.angle, y.octave);
}

WindowFeatures DetectWindow(const GrayImage& image,
                            const cv::Rect& rect,
                            const MatchOptions& options) {
  const cv::Mat full(static_cast<int>(image.rows()),
                     static_cast<int>(image.cols()),
                     CV_32F,
                     const_cast<float*>(image.data()));
  const cv::Mat window = full(rect);
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(0, 3, options.sift_contrast);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat gray8;
  if (options.detector == Detector::kSift) {
    gray8 = To8Bit(window);
    sift->detect(gray8, keypoints);
  } else {
    GrayImage block(rect.height, rect.width);
    for (int r = 0; r < rect.height; ++r)
      for (int c = 0; c < rect.width; ++c) block(r, c) = window.at<float>(r, c);
    const GrayImage wallis = WallisFilter(block, options.wallis);
    cv::Mat(rect.height, rect.width, CV_32F, const_cast<float*>(wallis.data()))
        .convertTo(gray8, CV_8U);
    FoerstnerOptions foerstner = options.foerstner;
    foerstner.max_points = options.max_keypoints;
    for (const InterestPoint& p : DetectFoerstner(wallis, foerstner)) {
      keypoints.emplace_back(
          cv::Point2f(static_cast<float>(p.position.x()), static_cast<float>(p.position.y())),
          static_cast<float>(options.descriptor_size_px),
          0.0f,
          static_cast<float>(p.weight));
    }
  }
  // OpenCV may return keypoints in thread-dependent order: sort before cutting to the strongest.
  std::stable_sort(keypoints.begin(), keypoints.end(), KeypointBefore);
  if (static_cast<int>(keypoints.size()) > options.max_keypoints)
    keypoints.resize(options.max_keypoints);
  WindowFeatures features;
  if (keypoints.empty()) return features;
  sift->compute(gray8, keypoints, features.descriptors);
  for (const cv::KeyPoint& k : keypoints)
    features.positions.emplace_back(k.pt.x + rect.x, k.pt.y + rect.y);
  return features;
}

struct Candidate {
  int cell = 0;
  double ratio = 0;
  Eigen::Vector2d uv_a, uv_b;
};

StitchObservation Row(const std::string& frame,
                      const std::string& point,
                      const std::string& sub,
                      const Eigen::Vector2d& uv,
                      double sigma_px) {
  return {frame, point, sub, uv.x(), uv.y(), sigma_px};
}

// Everything for one strip; appends rows and fills the report.
void MatchStrip(const calib::Camera& camera,
                const std::vector<GrayImage>& images,
                const OverlapStrip& strip,
                const std::string& frame,
                const MatchOptions& options,
                std::vector<StitchObservation>* rows,
                StripReport* report) {
  const calib::SubimageMapping& sa = camera.subimages[strip.a];
  const calib::SubimageMapping& sb = camera.subimages[strip.b];
  report->name = strip.name;
  const Eigen::Vector2d size = strip.in_virtual.sizes();
  const int nx = std::max(1, static_cast<int>(std::ceil(size.x() / options.cell_px)));
  const int ny = std::max(1, static_cast<int>(std::ceil(size.y() / options.cell_px)));
  report->cells = nx * ny;

  const WindowFeatures fa = DetectWindow(images[strip.a], PixelRect(strip.window_in_a), options);
  const WindowFeatures fb = DetectWindow(images[strip.b], PixelRect(strip.window_in_b), options);
  report->keypoints_a = static_cast<int>(fa.positions.size());
  report->keypoints_b = static_cast<int>(fb.positions.size());
  if (fa.positions.empty() || fb.positions.size() < 2) return;

  std::vector<std::vector<cv::DMatch>> knn;
  cv::BFMatcher(cv::NORM_L2).knnMatch(fa.descriptors, fb.descriptors, knn, 2);
  std::vector<Eigen::Vector2d> from, to;
  std::vector<double> ratios;
  for (const std::vector<cv::DMatch>& m : knn) {
    if (m.size() < 2 || m[1].distance <= 0) continue;
    const double ratio = m[0].distance / m[1].distance;
    if (ratio >= options.ratio) continue;
    const Eigen::Vector2d& uv_a = fa.positions[m[0].queryIdx];
    const Eigen::Vector2d& uv_b = fb.positions[m[0].trainIdx];
    const Eigen::Vector2d predicted = sb.SubFromVirtual(sa.VirtualFromSub(uv_a));
    if ((predicted - uv_b).norm() > options.margin_px) continue;
    from.push_back(uv_a);
    to.push_back(uv_b);
    ratios.push_back(ratio);
  }
  report->ratio_matches = static_cast<int>(from.size());
  const RansacResult ransac = RansacAffine(from, to, options.ransac);
  if (!ransac.ok) return;
  report->ransac_inliers = static_cast<int>(ransac.inliers.size());

  std::vector<Candidate> candidates;
  for (int i : ransac.inliers) {
    const Eigen::Vector2d cell_xy =
        (sa.VirtualFromSub(from[i]) - strip.in_virtual.min()) / options.cell_px;
    const int cx = std::clamp(static_cast<int>(std::floor(cell_xy.x())), 0, nx - 1);
    const int cy = std::clamp(static_cast<int>(std::floor(cell_xy.y())), 0, ny - 1);
    candidates.push_back({cy * nx + cx, ratios[i], from[i], to[i]});
  }
  std::stable_sort(
      candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
        return std::tie(x.cell, x.ratio) < std::tie(y.cell, y.ratio);
      });

  const int h = options.lsm.half_size_px;
  const GrayImage& image_a = images[strip.a];
  int point_number = 0, accepted_in_cell = 0, current_cell = -1;
  std::set<std::pair<long, long>> used_a;  // one tie per template pixel
  for (const Candidate& c : candidates) {
    if (c.cell != current_cell) {
      current_cell = c.cell;
      accepted_in_cell = 0;
    }
    if (accepted_in_cell >= options.points_per_cell) continue;
    Eigen::Vector2d uv_a = c.uv_a, uv_b = c.uv_b;
    double sigma = options.sigma_px;
    if (options.use_lsm) {
      const Eigen::Vector2i p_a(static_cast<int>(std::lround(c.uv_a.x())),
                                static_cast<int>(std::lround(c.uv_a.y())));
      if (p_a.x() < h || p_a.y() < h || p_a.x() + h >= image_a.cols() ||
          p_a.y() + h >= image_a.rows())
        continue;  // template would leave sub-image a: not a candidate for LSM
      if (!used_a.insert({p_a.x(), p_a.y()}).second) continue;
      ++report->lsm_tried;
      const LsmResult lsm = MatchLeastSquares(image_a,
                                              p_a,
                                              images[strip.b],
                                              ransac.mapping.Apply(p_a.cast<double>()),
                                              ransac.mapping.linear,
                                              options.lsm);
      if (lsm.status == LsmStatus::kLowCorrelation || lsm.status == LsmStatus::kPoorPrecision) {
        ++report->lsm_poor_precision;
        continue;
      }
      if (!lsm.ok()) {
        ++report->lsm_not_converged;
        continue;
      }
      uv_a = p_a.cast<double>();
      uv_b = lsm.position_in_b;
      sigma = std::max(options.min_sigma_px, lsm.SigmaMaxPx() / std::sqrt(2.0));
    }
    const std::string id = strip.name + "_" + std::to_string(point_number++);
    rows->push_back(Row(frame, id, sa.id, uv_a, sigma));
    rows->push_back(Row(frame, id, sb.id, uv_b, sigma));
    if (accepted_in_cell++ == 0) ++report->covered_cells;
  }
  report->points = point_number;
}

}  // namespace

Detector ParseDetector(const std::string& name) {
  if (name == "sift") return Detector::kSift;
  if (name == "foerstner") return Detector::kFoerstner;
  throw ConfigError("detector must be sift or foerstner (got " + name + ")");
}

void MatchOptions::Validate() const {
  if (!(margin_px >= 0)) throw ConfigError("margin_px must be >= 0");
  if (!(min_strip_width_px > 0)) throw ConfigError("min_strip_width_px must be > 0");
  if (!(sift_contrast > 0)) throw ConfigError("sift_contrast must be > 0");
  if (max_keypoints <= 0) throw ConfigError("max_keypoints must be > 0");
  if (!(ratio > 0 && ratio <= 1)) throw ConfigError("ratio must be in (0, 1]");
  if (!(cell_px > 0)) throw ConfigError("cell_px must be > 0");
  if (points_per_cell < 1) throw ConfigError("points_per_cell must be >= 1");
  if (!(sigma_px > 0)) throw ConfigError("sigma_px must be > 0");
  if (!(min_sigma_px > 0)) throw ConfigError("min_sigma_px must be > 0");
  if (descriptor_size_px < 4) throw ConfigError("descriptor_size_px must be >= 4");
  if (!(ransac.threshold_px > 0) || ransac.iterations < 1 || ransac.min_inliers < 3)
    throw ConfigError("ransac: threshold_px > 0, iterations >= 1, min_inliers >= 3 required");
  lsm.Validate();
  wallis.Validate();
  foerstner.Validate();
}

FrameMatches MatchFrame(const calib::Camera& camera,
                        const std::vector<GrayImage>& images,
                        const std::string& frame,
                        const MatchOptions& options) {
  options.Validate();
  AEROCAL_CHECK(images.size() == camera.subimages.size()) << "one image per sub-image";
  for (std::size_t k = 0; k < images.size(); ++k) {
    AEROCAL_CHECK(images[k].cols() == camera.subimages[k].width_px &&
                  images[k].rows() == camera.subimages[k].height_px)
        << "image of sub-image " << camera.subimages[k].id << " has the wrong format";
  }
  const std::vector<OverlapStrip> strips =
      PredictOverlapStrips(camera, options.margin_px, options.min_strip_width_px);
  std::vector<std::vector<StitchObservation>> rows(strips.size());
  FrameMatches out;
  out.strips.resize(strips.size());
  tbb::parallel_for(std::size_t{0}, strips.size(), [&](std::size_t s) {
    MatchStrip(camera, images, strips[s], frame, options, &rows[s], &out.strips[s]);
  });
  for (const auto& strip_rows : rows)
    out.observations.insert(out.observations.end(), strip_rows.begin(), strip_rows.end());
  return out;
}

void WriteMatchedObservations(const std::string& path,
                              const std::vector<StitchObservation>& observations,
                              bool append,
                              double default_sigma_px) {
  std::vector<StitchObservation> all;
  struct stat info {};
  if (append && ::stat(path.c_str(), &info) == 0) {
    all = ReadStitchObservations(path, default_sigma_px);
    std::set<std::string> existing;
    for (const StitchObservation& o : all) existing.insert(o.frame);
    for (const StitchObservation& o : observations)
      if (existing.count(o.frame))
        ThrowInputError({path, 0}, "frame " + o.frame + " is already in the file");
  }
  all.insert(all.end(), observations.begin(), observations.end());
  WriteStitchObservations(path, all);
}

}  // namespace aerocal::stitch
