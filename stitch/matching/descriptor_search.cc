// Search::kDescriptors (strip_candidates.h): SIFT, or Foerstner points with upright SIFT
// descriptors, in both windows; brute-force matching with Lowe's ratio test (Lowe 2004).
#include "stitch/image_io/cv_view.h"
#include "stitch/matching/strip_candidates.h"

#include <opencv2/features2d.hpp>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace aerocal::stitch {
namespace {

// Keypoints of one search window, in full sub-image pixels, with descriptors (one row each).
struct WindowFeatures {
  std::vector<Eigen::Vector2d> positions;
  cv::Mat descriptors;
};

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
  const cv::Mat window = CvView(image)(rect);
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(0, 3, options.sift_contrast);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat gray8;
  if (options.detector == Detector::kSift) {
    gray8 = To8Bit(window);
    sift->detect(gray8, keypoints);
  } else {
    const GrayImage block = image.block(rect.y, rect.x, rect.height, rect.width);
    const GrayImage wallis = WallisFilter(block, options.wallis);
    CvView(wallis).convertTo(gray8, CV_8U);
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

}  // namespace

cv::Rect PixelRect(const Eigen::AlignedBox2d& box) {
  const int x0 = static_cast<int>(std::floor(box.min().x()));
  const int y0 = static_cast<int>(std::floor(box.min().y()));
  const int x1 = static_cast<int>(std::ceil(box.max().x())) + 1;
  const int y1 = static_cast<int>(std::ceil(box.max().y())) + 1;
  return {x0, y0, x1 - x0, y1 - y0};
}

Eigen::Vector2d PredictInB(const calib::SubimageMapping& sa,
                           const calib::SubimageMapping& sb,
                           const Eigen::Vector2d& uv_a) {
  return sb.SubFromVirtual(sa.VirtualFromSub(uv_a));
}

StripCandidates DescriptorCandidates(const calib::Camera& camera,
                                     const std::vector<GrayImage>& images,
                                     const OverlapStrip& strip,
                                     const MatchOptions& options) {
  const WindowFeatures fa = DetectWindow(images[strip.a], PixelRect(strip.window_in_a), options);
  const WindowFeatures fb = DetectWindow(images[strip.b], PixelRect(strip.window_in_b), options);
  StripCandidates out;
  out.keypoints_a = static_cast<int>(fa.positions.size());
  out.keypoints_b = static_cast<int>(fb.positions.size());
  if (fa.positions.empty() || fb.positions.size() < 2) return out;

  std::vector<std::vector<cv::DMatch>> knn;
  cv::BFMatcher(cv::NORM_L2).knnMatch(fa.descriptors, fb.descriptors, knn, 2);
  const calib::SubimageMapping& sa = camera.subimages[strip.a];
  const calib::SubimageMapping& sb = camera.subimages[strip.b];
  for (const std::vector<cv::DMatch>& m : knn) {
    if (m.size() < 2 || m[1].distance <= 0) continue;
    const double ratio = m[0].distance / m[1].distance;
    if (ratio >= options.ratio) continue;
    const Eigen::Vector2d& uv_a = fa.positions[m[0].queryIdx];
    const Eigen::Vector2d& uv_b = fb.positions[m[0].trainIdx];
    if ((PredictInB(sa, sb, uv_a) - uv_b).norm() > options.margin_px) continue;
    out.in_a.push_back(uv_a);
    out.in_b.push_back(uv_b);
    out.score.push_back(ratio);
  }
  return out;
}

}  // namespace aerocal::stitch
