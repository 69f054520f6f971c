#include "triangulation/calibration/calibration.h"

#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "stitch/adjustment/f_distribution.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/calibration/group_change_power.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;

// Largest relative change of c the closed form may make to the camera file's value.
constexpr double kClosedFormFactor = 2.0;

Project Subset(const Project& project, const std::set<std::string>& images) {
  Project out = project;
  out.exposures.clear();
  out.observations.clear();
  out.points.clear();
  std::set<std::string> seen;
  for (const auto& e : project.exposures)
    if (images.count(e.image)) out.exposures.push_back(e);
  for (const auto& o : project.observations)
    if (images.count(o.image)) {
      out.observations.push_back(o);
      seen.insert(o.point);
    }
  for (const auto& p : project.points)
    if (seen.count(p.id)) out.points.push_back(p);
  return out;
}

}  // namespace

double ChiSquareQuantile(double p, int dof) {
  // chi^2(d) / d is the limit of F(d, n) for n -> infinity; 1e7 is that limit to ~1e-7.
  return dof * stitch::FDistributionQuantile(p, dof, 1e7);
}

CalibrationAdjustment RunCalibrationAdjustment(const Project& project,
                                               const AdjustOptions& options,
                                               bool control_cofactor) {
  CalibrationAdjustment out;
  BlockAdjustment adjustment(project, options);
  out.result = adjustment.Run();
  const std::string& camera = project.cameras.begin()->first;
  const calib::BlockId block = adjustment.InteriorBlock(camera);
  if (block >= 0 && out.result.solve.usable && out.result.solve.redundancy > 0 &&
      out.result.determinability.covariance_ok) {
    const calib::CovarianceReport cov =
        adjustment.builder().EstimateCovariance({block}, out.result.sigma0);
    const int size = project.cameras.begin()->second.interior.size();
    if (cov.ok) out.interior_covariance = cov.BlockCovariance(block, size);
    if (cov.ok && control_cofactor && out.result.sigma0 > 0)
      out.control_cofactor =
          ControlCofactor(adjustment, block, size, out.result.sigma0, out.interior_covariance);
  }
  return out;
}

StabilityReport GroupStability(const std::vector<GroupCalibration>& groups, double alpha) {
  StabilityReport report;
  report.alpha = alpha;
  if (groups.size() < 2) return report;
  const int n_groups = static_cast<int>(groups.size());
  const calib::CameraModelId model = groups.front().adjustment.result.cameras.empty()
                                         ? Model::kId
                                         : groups.front().adjustment.result.cameras[0].model;
  const std::vector<calib::ParamInfo> table = calib::CameraModelParams(model);
  std::vector<int> free;
  for (int k = 0; k < static_cast<int>(table.size()); ++k) {
    bool all = true;
    for (const auto& g : groups)
      all = all && !g.adjustment.result.cameras.empty() && g.adjustment.result.cameras[0].free[k];
    if (all) free.push_back(k);
  }
  const double critical =
      free.empty()
          ? 0.0
          : ChiSquareQuantile(1.0 - alpha / static_cast<double>(free.size()), n_groups - 1);
  for (int k : free) {
    StabilityRow row;
    row.parameter = std::string(table[k].name);
    row.unit = std::string(table[k].unit);
    double sum = 0, sum_w = 0, sum_wv = 0;
    bool sigmas_known = true;
    for (const auto& g : groups) {
      const auto& c = g.adjustment.result.cameras[0];
      row.values.push_back(c.estimated[k]);
      row.sigmas.push_back(c.sigma[k]);
      sum += c.estimated[k];
      sigmas_known = sigmas_known && c.sigma[k] > 0;
      if (c.sigma[k] > 0) {
        sum_w += 1.0 / (c.sigma[k] * c.sigma[k]);
        sum_wv += c.estimated[k] / (c.sigma[k] * c.sigma[k]);
      }
    }
    row.mean = sum / n_groups;
    double ss = 0;
    for (double v : row.values) ss += (v - row.mean) * (v - row.mean);
    row.spread = std::sqrt(ss / (n_groups - 1));
    row.dof = n_groups - 1;
    row.critical = critical;
    if (sigmas_known) {
      row.weighted_mean = sum_wv / sum_w;
      for (int g = 0; g < n_groups; ++g)
        row.chi2 += std::pow((row.values[g] - row.weighted_mean) / row.sigmas[g], 2);
      row.agree = row.chi2 <= critical;
      for (int g = 0; g < n_groups; ++g)
        row.detectable_change.push_back(
            DetectableGroupChange(row.sigmas, g, critical, report.power));
    } else {
      row.weighted_mean = row.mean;
      row.chi2 = std::nan("");
      row.agree = false;
    }
    if (!row.agree) {
      report.agree = false;
      report.flagged.push_back(
          sigmas_known ? StringPrintf("%s: the groups disagree beyond their sigmas (chi2 = %.3g > "
                                      "%.3g, %d degrees of freedom, alpha %.3g / %zu)",
                                      row.parameter.c_str(),
                                      row.chi2,
                                      critical,
                                      row.dof,
                                      alpha,
                                      free.size())
                       : row.parameter + ": a group's sigma is unknown, agreement not testable");
    }
    report.rows.push_back(row);
  }
  return report;
}

CalibrationRun Calibrate(const Project& input,
                         const CalibrateOptions& options,
                         const std::map<std::string, std::string>& group_of_image) {
  if (input.cameras.size() != 1)
    throw InputError("calibrate needs exactly one camera (got " +
                     std::to_string(input.cameras.size()) + ")");
  CalibrationRun run;
  Project project = input;
  run.camera = project.cameras.begin()->first;
  calib::Camera& camera = project.cameras.begin()->second;
  if (options.closed_form_c) {
    run.closed_form_c_mm = ClosedFormPrincipalDistance(project, run.camera);
    const double c_file = camera.c_mm();
    if (run.closed_form_c_mm &&
        *run.closed_form_c_mm<kClosedFormFactor * c_file&& * run.closed_form_c_mm> c_file /
            kClosedFormFactor)
      camera.SetPrincipalDistanceMm(*run.closed_form_c_mm);
  }
  run.start_c_mm = camera.c_mm();
  run.starts = StartFromResections(project, run.camera);
  project.exposures.clear();
  for (const auto& s : run.starts) project.exposures.push_back(s.exposure);
  const bool has_control =
      std::any_of(project.points.begin(), project.points.end(), [](const auto& p) {
        return p.role == PointRole::kControl && p.xyz_m;
      });
  run.all =
      RunCalibrationAdjustment(project, options.adjust, options.control_propagation && has_control);

  std::map<std::string, std::set<std::string>> groups;
  for (const auto& [image, group] : group_of_image) {
    if (!project.FindExposure(image))
      throw InputError("groups: image " + image + " has no observations");
    groups[group].insert(image);
  }
  for (const auto& [name, images] : groups) {
    if (images.size() < 2) throw InputError("groups: group " + name + " has fewer than two images");
    GroupCalibration g;
    g.group = name;
    g.images.assign(images.begin(), images.end());
    g.adjustment = RunCalibrationAdjustment(Subset(project, images), options.adjust);
    run.groups.push_back(std::move(g));
  }
  run.stability = GroupStability(run.groups, options.stability_alpha);
  run.project = std::move(project);
  return run;
}

}  // namespace aerocal::triangulation
