#include "stitch/rig/head_window.h"

#include "stitch/rig/rig_convert.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace aerocal::stitch {

HeadWindowSampler::HeadWindowSampler(const RigConverter& converter,
                                     int head,
                                     const GrayImage& image,
                                     const MapCorrectionGrid& grid)
    : image_(image), grid_(grid) {
  // Scaled as the resampler holds it (RigExposureAsSubimageCamera normalises virtual <- head by
  // its (2, 2) element), so that w > 0 in front of the head.
  Eigen::Matrix3d virtual_from_head = HeadFromVirtualHomography(converter, head).inverse();
  virtual_from_head /= virtual_from_head(2, 2);
  head_from_virtual_ = virtual_from_head.inverse();
}

std::optional<Eigen::Vector2f> HeadWindowSampler::HeadPosition(double col, double row) const {
  const Eigen::Matrix3d& m = head_from_virtual_;
  const double w = m(2, 0) * col + m(2, 1) * row + m(2, 2);
  if (!(w > 0)) return std::nullopt;
  float u = static_cast<float>((m(0, 0) * col + m(0, 1) * row + m(0, 2)) / w);
  float v = static_cast<float>((m(1, 0) * col + m(1, 1) * row + m(1, 2)) / w);
  if (grid_.step_px > 0) {  // as the resampler's CorrectionAlongRow, at one column
    const MapCorrectionGrid& g = grid_;
    const double gv = row / g.step_px;
    const int j = std::clamp(static_cast<int>(gv), 0, g.rows - 2);
    const float fv = static_cast<float>(gv - j);
    const float gu = static_cast<float>(col) * (1.0f / g.step_px);
    const int i = std::clamp(static_cast<int>(gu), 0, g.cols - 2);
    const float fu = gu - i;
    const float* top = g.duv.data() + 2 * (static_cast<size_t>(j) * g.cols + i);
    const float* bottom = top + 2 * g.cols;
    float d[2];
    for (int k = 0; k < 2; ++k) {
      const float t = top[k] + fu * (top[2 + k] - top[k]);
      const float b = bottom[k] + fu * (bottom[2 + k] - bottom[k]);
      d[k] = t + fv * (b - t);
    }
    u += d[0];
    v += d[1];
  }
  const float max_u = static_cast<float>(image_.cols() - 1);
  const float max_v = static_cast<float>(image_.rows() - 1);
  if (!(u >= 0.0f && u <= max_u && v >= 0.0f && v <= max_v)) return std::nullopt;
  return Eigen::Vector2f(u, v);
}

bool HeadWindowSampler::CoversDisc(double col, double row, double radius_px) const {
  if (!Covers(col, row)) return false;
  constexpr int kPoints = 16;
  for (int a = 0; a < kPoints; ++a) {
    const double angle = 2.0 * M_PI * a / kPoints;
    if (!Covers(col + radius_px * std::cos(angle), row + radius_px * std::sin(angle))) return false;
  }
  return true;
}

VirtualWindow HeadWindowSampler::Project(int x0, int y0, int cols, int rows) const {
  VirtualWindow out{x0, y0, GrayImage::Zero(rows, cols), GrayImage::Zero(rows, cols)};
  const int last_col = static_cast<int>(image_.cols()) - 2;
  const int last_row = static_cast<int>(image_.rows()) - 2;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const auto p = HeadPosition(x0 + c, y0 + r);
      if (!p) continue;
      const int i = std::min(static_cast<int>(p->x()), last_col);
      const int j = std::min(static_cast<int>(p->y()), last_row);
      const float fu = p->x() - i, fv = p->y() - j;
      const float top = image_(j, i) + fu * (image_(j, i + 1) - image_(j, i));
      const float bottom = image_(j + 1, i) + fu * (image_(j + 1, i + 1) - image_(j + 1, i));
      out.values(r, c) = top + fv * (bottom - top);
      out.weight(r, c) = 1.0f;
    }
  return out;
}

VirtualWindow HeadWindowSampler::ProjectSmoothed(
    int x0, int y0, int cols, int rows, double sigma_px) const {
  VirtualWindow out = Project(x0, y0, cols, rows);
  if (!(sigma_px > 0)) return out;
  cv::Mat values(rows, cols, CV_32F, out.values.data());
  cv::Mat weight(rows, cols, CV_32F, out.weight.data());
  cv::Mat blurred_values, blurred_weight;
  cv::GaussianBlur(values.mul(weight), blurred_values, cv::Size(0, 0), sigma_px);
  cv::GaussianBlur(weight, blurred_weight, cv::Size(0, 0), sigma_px);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const float w = blurred_weight.at<float>(r, c);
      out.values(r, c) = w > 1e-3f ? blurred_values.at<float>(r, c) / w : 0.0f;
    }
  return out;
}

int PrefilterBorderPx(double sigma_px) {
  if (!(sigma_px > 0)) return 0;
  const long size = std::lround(sigma_px * 8 + 1) | 1;  // OpenCV's size for CV_32F
  return static_cast<int>(size / 2);
}

}  // namespace aerocal::stitch
