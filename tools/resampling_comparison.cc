#include "tools/resampling_comparison.h"

#include "calib/core/error.h"
#include "stitch/quality/resampling_mtf.h"

#include <cmath>
#include <vector>

namespace aerocal::tools {
namespace {

constexpr double kCoverage = 2.0;

nlohmann::json NumberOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

// 100 (raw - other) / raw: a loss in percent of the raw MTF50 (null when either is undetermined).
nlohmann::json LossPercent(double raw, double other) {
  return NumberOrNull(100.0 * (raw - other) / raw);
}

// The same edge measured in the virtual image's file: its MTF50 with U, the measured loss and the
// measured against the predicted virtual MTF50, each with U (k = 2); or why it was not measured.
void AddVirtualMeasurement(const stitch::SlantedEdgeResult& raw,
                           double predicted,
                           const FoundEdgeRegion& found,
                           const VirtualWindow& window,
                           const stitch::SlantedEdgeOptions& options,
                           nlohmann::json* out) {
  stitch::PixelRegion r = found.in_virtual.region;
  r.col -= window.origin_px.x(), r.row -= window.origin_px.y();
  (*out)["virtual_image"] = window.path;
  (*out)["virtual_roi"] = {r.col, r.row, r.width, r.height};
  if (r.col < 0 || r.row < 0 || r.col + r.width > window.image->cols() ||
      r.row + r.height > window.image->rows()) {
    (*out)["virtual_reason"] = "the region leaves the virtual image file";
    return;
  }
  stitch::SlantedEdgeResult v;
  try {
    v = stitch::MeasureSlantedEdge(*window.image, r, options);
  } catch (const InputError& e) {
    (*out)["virtual_reason"] = e.what();
    return;
  }
  const double u = std::hypot(raw.mtf50_u_cy_px, v.mtf50_u_cy_px);
  (*out)["virtual_mtf50_cy_px"] = NumberOrNull(v.mtf50_cy_px);
  (*out)["virtual_mtf50_u_cy_px"] = v.mtf50_u_cy_px;
  (*out)["virtual_mtf50_expanded_cy_px"] = v.mtf50_expanded_cy_px;
  (*out)["virtual_angle_deg"] = v.angle_deg;
  (*out)["loss_cy_px"] = NumberOrNull(raw.mtf50_cy_px - v.mtf50_cy_px);
  (*out)["loss_expanded_cy_px"] = kCoverage * u;
  (*out)["loss_percent"] = LossPercent(raw.mtf50_cy_px, v.mtf50_cy_px);
  (*out)["loss_expanded_percent"] = NumberOrNull(100.0 * kCoverage * u / raw.mtf50_cy_px);
  (*out)["measured_minus_predicted_cy_px"] = NumberOrNull(v.mtf50_cy_px - predicted);
  (*out)["measured_minus_predicted_expanded_cy_px"] = kCoverage * u;
}

}  // namespace

nlohmann::json ResamplingComparisonJson(const stitch::SlantedEdgeResult& raw,
                                        const FoundEdgeRegion& found,
                                        const calib::SubimageMapping& sub,
                                        const VirtualWindow& window,
                                        const stitch::SlantedEdgeOptions& options) {
  const stitch::EdgeTargetRegion& v = found.in_virtual;
  // Bilinear interpolation at virtual pixel (U, V) weighs the raw samples by the fractional part
  // of (u, v) = SubFromVirtual(U, V): one shift per pixel of the virtual region.
  std::vector<Eigen::Vector2d> shifts;
  Eigen::Vector2d mean_shift = Eigen::Vector2d::Zero();
  for (int row = v.region.row; row < v.region.row + v.region.height; ++row)
    for (int col = v.region.col; col < v.region.col + v.region.width; ++col) {
      const Eigen::Vector2d uv = sub.SubFromVirtual(Eigen::Vector2d(col, row));
      shifts.push_back(uv - uv.array().floor().matrix());
      mean_shift += shifts.back();
    }
  mean_shift /= static_cast<double>(shifts.size());
  const Eigen::Vector2d along = (v.end_px - v.start_px).normalized();
  const Eigen::Vector2d normal(-along.y(), along.x());
  // The mapping's scale along the normal at the region's centre: raw px per virtual px.
  const Eigen::Vector2d centre(v.region.col + 0.5 * (v.region.width - 1),
                               v.region.row + 0.5 * (v.region.height - 1));
  const double scale =
      (sub.SubFromVirtual(centre + 0.5 * normal) - sub.SubFromVirtual(centre - 0.5 * normal))
          .norm();
  const double predicted = stitch::PredictResampledMtf50AtShifts(raw, shifts, normal, scale);
  const double uniform = stitch::PredictResampledMtf50(
      raw, stitch::Interpolation::kBilinear, std::atan2(normal.y(), normal.x()));
  nlohmann::json out = {
      {"interpolation", "bilinear"},
      {"virtual_region_px", {v.region.col, v.region.row, v.region.width, v.region.height}},
      {"mean_shift_px", {mean_shift.x(), mean_shift.y()}},
      {"raw_per_virtual_px", scale},
      {"predicted_virtual_mtf50_cy_px", NumberOrNull(predicted)},
      {"predicted_loss_percent", LossPercent(raw.mtf50_cy_px, predicted)},
      {"uniform_phase_virtual_mtf50_cy_px", NumberOrNull(uniform)},
      {"uniform_phase_loss_percent", LossPercent(raw.mtf50_cy_px, uniform)}};
  if (window.image != nullptr) AddVirtualMeasurement(raw, predicted, found, window, options, &out);
  return out;
}

nlohmann::json RegionCentreJson(const stitch::PixelRegion& region,
                                const Eigen::Vector2i& origin_px) {
  return {origin_px.x() + region.col + 0.5 * (region.width - 1),
          origin_px.y() + region.row + 0.5 * (region.height - 1)};
}

}  // namespace aerocal::tools
