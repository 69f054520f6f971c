#include "stitch/matching/interest_operators.h"

#include "calib/core/error.h"
#include "stitch/image_io/cv_view.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace aerocal::stitch {
namespace {

void RequireOddWindow(int value, const char* field) {
  if (value < 3 || value % 2 == 0)
    throw ConfigError(std::string(field) + " must be odd and >= 3 (got " + std::to_string(value) +
                      ")");
}

}  // namespace

void WallisOptions::Validate() const {
  RequireOddWindow(window_px, "wallis.window_px");
  if (!(target_std > 0)) throw ConfigError("wallis.target_std must be > 0");
  if (!(contrast >= 0 && contrast <= 1)) throw ConfigError("wallis.contrast must be in 0..1");
  if (!(brightness >= 0 && brightness <= 1)) throw ConfigError("wallis.brightness must be in 0..1");
}

void FoerstnerOptions::Validate() const {
  RequireOddWindow(window_px, "foerstner.window_px");
  RequireOddWindow(suppression_px, "foerstner.suppression_px");
  if (!(min_roundness >= 0 && min_roundness <= 1))
    throw ConfigError("foerstner.min_roundness must be in 0..1");
  if (!(weight_factor > 0)) throw ConfigError("foerstner.weight_factor must be > 0");
  if (max_points <= 0) throw ConfigError("foerstner.max_points must be > 0");
}

GrayImage WallisFilter(const GrayImage& image, const WallisOptions& options) {
  options.Validate();
  const cv::Mat g = CvView(image);
  const cv::Size window(options.window_px, options.window_px);
  cv::Mat mean, mean_sq;
  cv::boxFilter(g, mean, CV_32F, window, cv::Point(-1, -1), true, cv::BORDER_REFLECT);
  cv::boxFilter(g.mul(g), mean_sq, CV_32F, window, cv::Point(-1, -1), true, cv::BORDER_REFLECT);
  GrayImage out(image.rows(), image.cols());
  const double c = options.contrast, b = options.brightness;
  const double sf = options.target_std, mf = options.target_mean;
  for (int r = 0; r < g.rows; ++r) {
    for (int col = 0; col < g.cols; ++col) {
      const double m = mean.at<float>(r, col);
      const double s = std::sqrt(std::max(0.0, mean_sq.at<float>(r, col) - m * m));
      const double gain = c * sf / (c * s + (1.0 - c) * sf);
      out(r, col) = static_cast<float>((image(r, col) - m) * gain + b * mf + (1.0 - b) * m);
    }
  }
  return out;
}

std::vector<InterestPoint> DetectFoerstner(const GrayImage& image,
                                           const FoerstnerOptions& options) {
  options.Validate();
  const cv::Mat g = CvView(image);
  cv::Mat gx, gy;  // central differences: d/dcol, d/drow
  const cv::Mat kx = (cv::Mat_<float>(1, 3) << -0.5f, 0.0f, 0.5f);
  cv::filter2D(g, gx, CV_32F, kx, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
  cv::filter2D(g, gy, CV_32F, kx.t(), cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
  const cv::Size window(options.window_px, options.window_px);
  cv::Mat nxx, nxy, nyy;
  cv::boxFilter(gx.mul(gx), nxx, CV_32F, window, cv::Point(-1, -1), false, cv::BORDER_REFLECT);
  cv::boxFilter(gx.mul(gy), nxy, CV_32F, window, cv::Point(-1, -1), false, cv::BORDER_REFLECT);
  cv::boxFilter(gy.mul(gy), nyy, CV_32F, window, cv::Point(-1, -1), false, cv::BORDER_REFLECT);
  cv::Mat w(g.size(), CV_32F), q(g.size(), CV_32F);
  for (int r = 0; r < g.rows; ++r) {
    for (int c = 0; c < g.cols; ++c) {
      const double a = nxx.at<float>(r, c), b = nxy.at<float>(r, c), d = nyy.at<float>(r, c);
      const double det = a * d - b * b, trace = a + d;
      w.at<float>(r, c) = trace > 0 ? static_cast<float>(det / trace) : 0.0f;
      q.at<float>(r, c) = trace > 0 ? static_cast<float>(4.0 * det / (trace * trace)) : 0.0f;
    }
  }
  const double threshold = options.weight_factor * cv::mean(w)[0];
  cv::Mat local_max;
  cv::dilate(w,
             local_max,
             cv::getStructuringElement(cv::MORPH_RECT,
                                       cv::Size(options.suppression_px, options.suppression_px)));
  // Points closer to the border than the tensor window have truncated support: skip them.
  const int border = options.window_px / 2 + 1;
  std::vector<InterestPoint> points;
  for (int r = border; r < g.rows - border; ++r) {
    for (int c = border; c < g.cols - border; ++c) {
      const float value = w.at<float>(r, c);
      if (value <= threshold || value < local_max.at<float>(r, c)) continue;
      if (q.at<float>(r, c) < options.min_roundness) continue;
      points.push_back({Eigen::Vector2d(c, r), value, q.at<float>(r, c)});
    }
  }
  std::stable_sort(
      points.begin(), points.end(), [](const InterestPoint& x, const InterestPoint& y) {
        return x.weight > y.weight;
      });
  if (static_cast<int>(points.size()) > options.max_points) points.resize(options.max_points);
  return points;
}

}  // namespace aerocal::stitch
