// Adjust(): one adjustment, or with a robust start a Cauchy-loss adjustment whose solution and
// gross-error screening start the clean one (see AdjustOptions::robust_start).
#include "calib/core/csv.h"
#include "triangulation/adjustment/block_adjustment.h"

#include <algorithm>
#include <cmath>

namespace aerocal::triangulation {

int AdjustStages(const AdjustOptions& options) {
  return (options.robust_start ? 2 : 1) * BlockAdjustment::kRunStages;
}

AdjustmentResult Adjust(const Project& project, const AdjustOptions& options, Progress* progress) {
  if (!options.robust_start) {
    BlockAdjustment adjustment(project, options);
    return adjustment.Run(progress);
  }
  AdjustOptions robust = options;
  robust.data_snooping = false;
  robust.estimate_covariance = false;
  calib::LossOptions loss;
  loss.kind = calib::LossKind::kCauchy;
  loss.scale = options.robust_scale_sigma;
  AdjustmentResult start;
  {
    BlockAdjustment adjustment(project, robust, SubimageObservations::kMapWithCameraFile, loss);
    start = adjustment.Run(progress);
  }
  // Observations far outside the robust solution's spread are gross errors: a robust scale
  // (1.4826 median |v / sigma| over all components) and a cut at `robust_reject_sigma` scales.
  std::vector<double> abs_w;
  for (const auto& v : start.residuals)
    if (v.used)
      for (int k = 0; k < 2; ++k) abs_w.push_back(std::abs(v.residual_px(k)) / v.sigma_px);
  std::vector<RejectedObservation> pre_rejected;
  std::vector<ObservationResidual> pre_rejected_residuals;  // listed with their robust residual
  Project next = project;
  if (!abs_w.empty()) {
    std::nth_element(abs_w.begin(), abs_w.begin() + abs_w.size() / 2, abs_w.end());
    const double scale = std::max(1e-12, 1.4826 * abs_w[abs_w.size() / 2]);
    std::vector<bool> drop(project.observations.size(), false);
    for (const auto& v : start.residuals) {
      const double w = v.residual_px.norm() / v.sigma_px / scale;
      if (!v.used || w <= options.robust_reject_sigma) continue;
      for (size_t i = 0; i < project.observations.size(); ++i) {
        const auto& o = project.observations[i];
        if (!drop[i] && o.image == v.image && o.point == v.point && o.subimage.empty() &&
            o.pixel == v.measured_px) {
          drop[i] = true;
          pre_rejected.push_back({v.image,
                                  v.point,
                                  v.measured_px,
                                  Eigen::Vector2d(v.residual_px.x(), -v.residual_px.y()),
                                  w,
                                  std::string()});
          pre_rejected_residuals.push_back(v);
          pre_rejected_residuals.back().used = false;
          break;
        }
      }
    }
    next.observations.clear();
    for (size_t i = 0; i < project.observations.size(); ++i)
      if (!drop[i]) next.observations.push_back(project.observations[i]);
  }
  // The robust solution becomes the starting values; surveyed coordinates stay the survey.
  for (auto& e : next.exposures)
    for (const auto& s : start.exposures)
      if (s.image == e.image) {
        e.center_m = s.center_m;
        e.opk_rad = s.opk_rad;
      }
  for (const auto& c : start.cameras) next.cameras.at(c.id).interior = c.estimated;
  for (auto& p : next.points)
    if (p.role == PointRole::kTie && start.points_m.count(p.id)) p.xyz_m = start.points_m.at(p.id);
  BlockAdjustment adjustment(next, options);
  AdjustmentResult result = adjustment.Run(progress);
  for (auto& c : result.cameras) c.initial = project.cameras.at(c.id).interior;
  result.rejected.insert(result.rejected.begin(), pre_rejected.begin(), pre_rejected.end());
  result.residuals.insert(
      result.residuals.end(), pre_rejected_residuals.begin(), pre_rejected_residuals.end());
  result.notes.push_back("started from a robust (Cauchy, " +
                         FormatNumber(options.robust_scale_sigma, 3) + " sigma) adjustment");
  return result;
}

}  // namespace aerocal::triangulation
