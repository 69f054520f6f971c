#include "triangulation/calibration/calibration_json.h"

#include "calib/camera/camera_model.h"

#include <cmath>
#include <string>

namespace aerocal::triangulation {
namespace {

// The model's parameter names (its table) of a camera estimate.
std::vector<std::string> ParamNames(const CameraEstimate& c) {
  std::vector<std::string> names;
  for (const calib::ParamInfo& info : calib::CameraModelParams(c.model))
    names.emplace_back(info.name);
  return names;
}

nlohmann::json InteriorJson(const CameraEstimate& c, const calib::InteriorParams& p) {
  nlohmann::json j;
  const std::vector<std::string> names = ParamNames(c);
  for (size_t k = 0; k < names.size(); ++k) j[names[k]] = p[k];
  return j;
}

// One run of a group with its name and images.
nlohmann::json GroupJson(const GroupCalibration& g) {
  nlohmann::json j = CalibrationRunToJson(g.adjustment.result);
  j["group"] = g.group;
  j["images"] = g.images;
  return j;
}

}  // namespace

nlohmann::json InteriorCovarianceToJson(const Eigen::MatrixXd& cov, const CameraEstimate& c) {
  if (cov.rows() != c.estimated.size()) return nullptr;
  const std::vector<std::string> table = ParamNames(c);
  std::vector<int> free;
  for (int k = 0; k < c.estimated.size(); ++k)
    if (c.free[k]) free.push_back(k);
  nlohmann::json names = nlohmann::json::array(), cv = nlohmann::json::array(),
                 rho = nlohmann::json::array();
  for (int a : free) {
    names.push_back(table[a]);
    nlohmann::json row = nlohmann::json::array(), rrow = nlohmann::json::array();
    for (int b : free) {
      row.push_back(cov(a, b));
      const double d = std::sqrt(cov(a, a) * cov(b, b));
      rrow.push_back(d > 0 ? cov(a, b) / d : 0.0);
    }
    cv.push_back(row);
    rho.push_back(rrow);
  }
  return {{"names", names}, {"covariance", cv}, {"correlation", rho}};
}

nlohmann::json CalibrationRunToJson(const AdjustmentResult& r) {
  nlohmann::json j = {{"converged", r.converged()},
                      {"valid", r.valid},
                      {"sigma0", r.sigma0},
                      {"sigma0_px", r.sigma0_px},
                      {"redundancy", r.solve.redundancy}};
  if (!r.cameras.empty()) {
    const CameraEstimate& c = r.cameras[0];
    j["estimated"] = InteriorJson(c, c.estimated);
    nlohmann::json s;
    const std::vector<std::string> names = ParamNames(c);
    for (size_t k = 0; k < names.size(); ++k)
      s[names[k]] = c.free[k] && r.determinability.covariance_ok ? nlohmann::json(c.sigma[k])
                                                                 : nlohmann::json();
    j["sigma"] = s;
  }
  j["check"] = PointStatisticsToJson(r.check);
  return j;
}

nlohmann::json StabilityToJson(const StabilityReport& s) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& r : s.rows)
    rows.push_back(
        {{"parameter", r.parameter},
         {"unit", r.unit},
         {"values", r.values},
         {"sigmas", r.sigmas},
         {"detectable_change",
          r.detectable_change.empty() ? nlohmann::json() : nlohmann::json(r.detectable_change)},
         {"mean", r.mean},
         {"spread", r.spread},
         {"weighted_mean", r.weighted_mean},
         {"chi2", std::isfinite(r.chi2) ? nlohmann::json(r.chi2) : nlohmann::json()},
         {"critical", r.critical},
         {"dof", r.dof},
         {"agree", r.agree}});
  return {{"alpha", s.alpha},
          {"power", s.power},
          {"agree", s.agree},
          {"rows", rows},
          {"flagged", s.flagged}};
}

nlohmann::json CalibrationToJson(const CalibrationRun& run,
                                 const std::vector<BudgetQuantity>& budget,
                                 const std::vector<double>& radii_mm,
                                 double c_camera_file_mm) {
  nlohmann::json cal;
  nlohmann::json starts = nlohmann::json::array();
  for (const auto& s : run.starts)
    starts.push_back({{"image", s.exposure.image},
                      {"method", s.method},
                      {"n_points", s.n_points},
                      {"rms_px", s.rms_px}});
  cal["start"] = {{"c_camera_file_mm", c_camera_file_mm},
                  {"c_closed_form_mm",
                   run.closed_form_c_mm ? nlohmann::json(*run.closed_form_c_mm) : nlohmann::json()},
                  {"c_start_mm", run.start_c_mm},
                  {"resections", starts}};
  int n_control = 0, n_check = 0;
  for (const auto& p : run.project.points) {
    n_control += p.role == PointRole::kControl;
    n_check += p.role == PointRole::kCheck;
  }
  cal["data"] = {{"images", run.starts.size()},
                 {"observations", run.project.observations.size()},
                 {"control_points", n_control},
                 {"check_points", n_check},
                 {"groups", run.groups.size()}};
  const AdjustmentResult& r = run.all.result;
  if (!r.cameras.empty())
    cal["interior_covariance"] =
        InteriorCovarianceToJson(run.all.interior_covariance, r.cameras[0]);
  cal["groups"] = nlohmann::json::array();
  for (const auto& g : run.groups) cal["groups"].push_back(GroupJson(g));
  cal["stability"] = StabilityToJson(run.stability);
  cal["uncertainty"] = BudgetToJson(budget);
  cal["radii_mm"] = radii_mm;
  return cal;
}

}  // namespace aerocal::triangulation
